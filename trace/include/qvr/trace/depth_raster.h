// A CPU z-buffer over a Scene for the workload recorder (paper §5, §6.1): per pixel the nearest
// surface's depth and object, and how many fragments an early-depth-test GPU shades in draw
// order (overdraw), which the OpenGL renderer cannot report per pixel.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "qvr/core/image.h"
#include "qvr/scene/scene.h"

namespace qvr {

// The raster of one view at 1/scale of the full resolution: raster pixel (i, j) covers the
// full-resolution pixels [i·scale, (i+1)·scale) × [j·scale, (j+1)·scale), as a layer at that
// scale does (docs/RENDER.md), and is sampled at its centre.
struct DepthRaster {
    int width = 0;
    int height = 0;
    int scale = 1;
    std::vector<float> depth_m;    // eye-space depth along −z of the nearest surface; 0 = none
    std::vector<int32_t> object;   // its object id (DepthRasterizer's grouping), −1 = none
    std::vector<uint16_t> shaded;  // fragments that passed the depth test, in draw order
    std::vector<uint32_t> object_triangles;  // per object: triangles surviving trivial reject
    std::vector<uint32_t> object_pixels;     // per object: raster pixels it ends up owning
};

// Groups the scene's triangles into "objects" — each draw batch split by a grid of
// cell_m-sided cells over triangle centroids — because a level's batches (one per texture and
// lightmap) span the whole level, while §6.1's static design needs the nearest *object*.
class DepthRasterizer {
public:
    explicit DepthRasterizer(const Scene& scene, double cell_m = 1.0);

    int objectCount() const { return static_cast<int>(m_object_bounds.size()); }
    const Aabb& objectBounds(int id) const { return m_object_bounds[static_cast<size_t>(id)]; }
    int objectBatch(int id) const { return m_object_batch[static_cast<size_t>(id)]; }

    // Rasterizes every triangle (both faces, in batch order, like the renderer) with the
    // view-projection of a full-resolution full_width × full_height view (row 0 at the top),
    // into `out` at 1/scale of that resolution. Triangles are clipped against the near plane;
    // the other planes only bound the pixel loops.
    void rasterize(const glm::mat4& view, const glm::mat4& projection, int full_width,
                   int full_height, int scale, DepthRaster& out) const;

private:
    const Scene& m_scene;
    std::vector<int32_t> m_tri_object;  // per triangle
    std::vector<Aabb> m_object_bounds;
    std::vector<int> m_object_batch;
};

// Distance from a point to a box (0 inside).
double distanceToBox(const glm::vec3& p, const Aabb& box);

// A 16-bit depth image as two 8-bit grey planes a video codec can carry (docs/RECORDING.md):
// d16 = depth / step (65535 = nothing drawn), high = d16 >> 8, low = d16 & 255 folded
// (mirrored on odd high bytes) so it never jumps from 255 to 0 where depth crosses a high-byte
// step — a jump the codec would pay for (Pece et al., "Adapting standard video codecs for depth
// streaming", 2011).
inline constexpr double kDepthStepM = 0.002;
void depthPlanes(const DepthRaster& raster, ImageRgba8& high, ImageRgba8& low);

// Box-filters an image by 2 in each direction (odd edges average what exists): applied k times
// it gives the layer a renderer would produce at scale 2^k up to filtering.
void halveImage(const ImageRgba8& in, ImageRgba8& out);

}  // namespace qvr
