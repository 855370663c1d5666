// What a renderer draws: each batch of a Scene split into spatially compact clusters of a few
// hundred triangles, so that CPU frustum culling removes what a layer cannot see even when a
// level's batches (one per texture × lightmap) span the whole level. The fovea layer then
// submits roughly the triangles of its view cone, which is what its cost should scale with
// (paper §4.1: local rendering time follows the fovea's triangle count).
#pragma once

#include <cstdint>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/render/camera.h"
#include "qvr/scene/scene.h"

namespace qvr {

struct DrawCluster {
    uint32_t first_index = 0;  // into DrawList::indices
    uint32_t index_count = 0;
    uint32_t batch = 0;  // the Scene batch it came from (texture and lightmap)
    Aabb bounds;
};

// A coarser version of every cluster (docs/RENDER.md "Level of detail"): vertex clustering on a
// grid of cubic cells — every vertex moves to the centre of its cell, triangles that collapse
// are dropped — so no vertex moves by more than half a cell diagonal, and neighbouring clusters
// and batches move shared positions alike (no cracks).
struct DrawLodLevel {
    float cell_m = 0.0f;
    std::vector<uint32_t> first_index;  // per cluster, into DrawList::indices
    std::vector<uint32_t> index_count;  // per cluster; may be 0 when the cluster vanished
};

struct DrawList {
    // The scene's indices with each batch's triangles reordered along a Morton curve of their
    // centroids; every batch keeps its index range, so a batch is still one contiguous span.
    // The LOD levels' indices follow the scene's.
    std::vector<uint32_t> indices;
    std::vector<DrawCluster> clusters;  // in index order
    // Vertices the LOD levels add, indexed after the scene's own: vertex
    // scene.vertices.size() + i is lod_vertices[i].
    std::vector<SceneVertex> lod_vertices;
    std::vector<DrawLodLevel> lods;  // finest first; each cell twice the previous
};

struct LodOptions {
    int levels = 6;
    // The finest cell; 0 picks the scene's box diagonal / 4096.
    float finest_cell_m = 0.0f;
};

// Adds LOD levels to a draw list built from `scene` (replacing any it had).
void buildLods(DrawList& list, const Scene& scene, const LodOptions& options = {});

inline constexpr uint32_t kDefaultClusterTriangles = 256;

// What drawing relies on: batches of whole triangles inside the index buffer, indices inside
// the vertex buffer, texture and lightmap indices that exist, texel arrays of the stated size.
Status checkDrawable(const Scene& scene);

// Builds the draw list of a scene that passes checkDrawable. Batches of at most
// cluster_triangles triangles stay whole and keep their own bounds.
DrawList buildDrawList(const Scene& scene, uint32_t cluster_triangles = kDefaultClusterTriangles);

// One draw call: a contiguous run of visible clusters of one batch.
struct DrawRange {
    uint32_t first_index = 0;
    uint32_t index_count = 0;
    uint32_t batch = 0;
};

struct DrawSelection {
    std::vector<DrawRange> draws;
    uint64_t triangles = 0;
    uint32_t clusters_drawn = 0;
    uint32_t clusters_culled = 0;
    uint32_t clusters_coarsened = 0;  // drawn at a LOD level
    uint32_t clusters_skipped = 0;    // in the frustum but wholly inside the view's hole
};

// True when the box lies wholly inside the cone (apex, unit axis, half-angle): its bounding
// sphere's angular radius seen from the apex plus its centre's angle to the axis fits.
bool boxInsideCone(const Aabb& box, const glm::vec3& apex, const glm::vec3& axis,
                   float half_angle_rad);

// The clusters a view may see (conservative plane test on their boxes), merged into draw calls.
// With lod_error_px > 0 and LOD levels built, each cluster is drawn at the coarsest level whose
// largest vertex move (half a cell diagonal), seen from the eye at the cluster box's nearest
// point, stays within lod_error_px of the view's own pixels. Clusters wholly inside the view's
// hole (RenderView::skip_*) are left out.
DrawSelection selectDraws(const DrawList& list, const RenderView& view, float lod_error_px = 0.0f);

// LIWC's pre-render input (paper §4.1) at the cost of one pass over the clusters: adds to
// rings[k] the triangles the view would draw within eccentricity [k·ring_deg, (k+1)·ring_deg)
// of `axis` (world space, unit, from the view's eye). Each cluster in the frustum counts the
// triangles of the level of detail selectDraws() would pick and spreads them evenly over the
// rings its bounding sphere spans; the last ring is open-ended. Exact in total, approximate by
// ring within a cluster's angular size (docs/LIWC.md "Ring counts").
void addTrianglesPerRing(const DrawList& list, const RenderView& view, float lod_error_px,
                         const glm::vec3& axis, double ring_deg, std::vector<double>& rings);

}  // namespace qvr
