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

struct DrawList {
    // The scene's indices with each batch's triangles reordered along a Morton curve of their
    // centroids; every batch keeps its index range, so a batch is still one contiguous span.
    std::vector<uint32_t> indices;
    std::vector<DrawCluster> clusters;  // in index order
};

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
};

// The clusters a view may see (conservative plane test on their boxes), merged into draw calls.
DrawSelection selectDraws(const DrawList& list, const RenderView& view);

}  // namespace qvr
