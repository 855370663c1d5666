// The server's periphery in one geometry pass per eye (docs/RENDER.md "One-pass periphery"): the
// middle layer's texel grid, extended to cover the outer layer, is rendered once; the middle
// layer is a crop of it and the outer layer its box-filtered reduction. On a vertex-bound GPU
// (llvmpipe, or any GPU with dense geometry and small layers) this halves the server's geometry
// work against rendering the two layers as two sub-frusta, and the outer layer comes out
// anti-aliased (an area average of s1 texels) instead of point-sampled at s2.
#pragma once

#include <cstdint>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"
#include "qvr/render/camera.h"
#include "qvr/render/renderer.h"

namespace qvr {

// The extended grid: origin (x0, y0) in full-resolution pixels (may be negative or fractional),
// the middle layer's scale, and its size in texels. Middle texel (i, j) is grid texel
// (i + middle_col, j + middle_row).
struct PeripheryGrid {
    double x0 = 0.0;
    double y0 = 0.0;
    double scale = 1.0;
    int width_px = 0;
    int height_px = 0;
    int middle_col = 0;
    int middle_row = 0;

    int64_t pixels() const { return static_cast<int64_t>(width_px) * height_px; }
};

// The grid for one eye of a plan; empty (0 × 0) when the eye lacks a middle or an outer layer
// or the outer layer is not coarser than the middle one.
PeripheryGrid peripheryGrid(const EyeLayers& layers);

// Whether one pass is the cheaper way for this eye: both layers present and the extended grid
// at most `max_fill_ratio` times the texels of the two layers (the fill the pass adds in
// exchange for one geometry pass fewer).
bool onePassPays(const EyeLayers& layers, double max_fill_ratio = 8.0);

// The outer layer's texels as area averages of the grid's: outer texel (i, j) covers
// full-resolution pixels [o.x0 + i·s2, o.x0 + (i+1)·s2) × …, the grid's texels are weighted by
// their overlap with that footprint (clamped to the grid's edge). Alpha is 255.
void reduceToOuter(const ImageRgba8& grid_image, const PeripheryGrid& grid, const LayerRect& outer,
                   ImageRgba8& out);

// Copies middle texels out of the grid image.
void cropMiddle(const ImageRgba8& grid_image, const PeripheryGrid& grid, const LayerRect& middle,
                ImageRgba8& out);

// Renders the middle and outer layers of one eye in one pass (onePassPays should hold; an eye
// without both layers is an error). `scratch` holds the grid image between calls.
Expected<RenderStats> renderPeriphery(Renderer& renderer, const HmdProfile& profile,
                                      const LayerPlan& plan, const Pose& head, Eye eye,
                                      ImageRgba8& middle, ImageRgba8& outer, ImageRgba8& scratch,
                                      const CameraOptions& options = {});

}  // namespace qvr
