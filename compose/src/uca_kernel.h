// The per-tile UCA kernel (paper §4.2, Eq. 4) in two builds that must agree: a Highway kernel
// that maps and filters a vector of pixels at a time, and its scalar twin. Private to compose.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "qvr/compose/uca.h"
#include "qvr/foveation/hmd_profile.h"

namespace qvr::detail {

// One layer as the kernel sees it: packed RGBA8 texels and the affine map from full-resolution
// rendered-image coordinates to texel coordinates, lx = px·inv_scale + offset_x.
struct KernelLayer {
    const uint8_t* texels = nullptr;  // RGBA8, rows of `width` texels
    int width = 0;
    int height = 0;
    float inv_scale = 1.0f;
    float offset_x = 0.0f;
    float offset_y = 0.0f;
};

// Everything the kernel needs for one eye of one frame, in float. Slots are the present layers
// from the inside out; slot k+1 takes over from slot k across a blend band.
struct KernelParams {
    // Display pixel (u, v) → tangent coordinates: xt = u·ax + bx, yt = v·ay + by.
    float ax = 0, bx = 0, ay = 0, by = 0;
    float k1 = 0, k2 = 0;
    float chroma_red = 1, chroma_blue = 1;
    bool chroma = false;  // per-channel maps when the red or blue scale differs from 1
    // When set, the display pixel is the rendered pixel (no lens, no rotation): the composition
    // pass of the two-pass reference.
    bool identity_map = false;
    // Display → rendered eye space, row-major; R = xd·col0 + yd·col1 − col2.
    float m[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    float fx = 1, fy = 1, cx = 0, cy = 0;
    float width = 0, height = 0;  // the rendered image, in full-resolution pixels
    float gaze[3] = {0, 0, -1};   // unit gaze in rendered eye space
    int slot_count = 0;
    KernelLayer slots[3];
    // Blend ramps in cos(eccentricity): t = clamp((c_hi − cos e)·inv, 0, 1) is the share of the
    // outer layer of a border. inv = 0 disables a border.
    float border_c_hi[2] = {2, 2};
    float border_inv[2] = {0, 0};
};

// The map of one display row, in the form the kernels evaluate it: with xt = u·ax + bx,
// r² = xt² + yt², f = (1 + k1·r² + k2·r⁴)·chroma,
//   num_x = f·(xt·mx + cx_row) − ox,  num_y = f·(xt·my + cy_row) − oy,  depth = dz − f·(xt·mz +
//   cz_row)
// and px = num_x/depth + cx, py = num_y/depth + cy: the rotation's columns pre-multiplied by the
// focal lengths, the row's yt folded into constants. Both kernels build it with rowMap().
struct RowMap {
    float yt = 0, yt2 = 0;
    float mx = 0, cx_row = 0, ox = 0;
    float my = 0, cy_row = 0, oy = 0;
    float mz = 0, cz_row = 0, dz = 0;
};

inline RowMap rowMap(const KernelParams& p, float v) {
    RowMap r;
    // Written as products and one fused add so that the vector and scalar builds agree.
    r.yt = v * p.ay + p.by;
    r.yt2 = r.yt * r.yt;
    r.mx = p.fx * p.m[0];
    r.cx_row = (p.fx * p.m[1]) * r.yt;
    r.ox = p.fx * p.m[2];
    r.my = -p.fy * p.m[3];
    r.cy_row = (-p.fy * p.m[4]) * r.yt;
    r.oy = -p.fy * p.m[5];
    r.mz = p.m[6];
    r.cz_row = p.m[7] * r.yt;
    r.dz = p.m[8];
    return r;
}

// The output window of one tile: rows y0..y1, columns x0..x1 (half-open), written into `out`
// (RGBA8, `out_stride_px` pixels a row). slot_mask: bit k set when slot k may contribute; a
// single bit takes the single-layer path.
struct TileJob {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    uint8_t slot_mask = 0;
    uint8_t* out = nullptr;
    size_t out_stride_px = 0;
    // Write with streaming (non-temporal) stores where aligned: the display image is written
    // once and read by someone else, so it need not displace the layers from the caches.
    bool stream = false;
};

inline constexpr uint32_t kOpaqueBlack = 0xFF000000u;

void ucaTileScalar(const KernelParams& p, const TileJob& job);
// The kernel parameters of the composition pass (identity map) for one eye of a validated frame:
// its slots and blend ramps, shared with the OpenCV anchor so that all paths blend alike.
KernelParams composeParams(const HmdProfile& profile, const LayerFrame& frame, int eye,
                           double blend_band_texels);
// The lens + timewarp map of one eye (no slots): what a remap-based path needs to build its maps.
KernelParams timewarpParams(const HmdProfile& profile, const Pose& render_pose,
                            const Pose& display_pose, const Gaze& gaze);
// The present layers of one eye from the inside out, with the eccentricity where each ends and
// the width of the Eq. 4 blend band just inside that end (docs/UCA.md).
struct SlotInfo {
    int count = 0;
    int layer[3] = {0, 0, 0};  // 0 fovea, 1 middle, 2 outer
    double radius_deg[3] = {std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::infinity()};
    double band_deg[3] = {0, 0, 0};
};
SlotInfo slotBands(const HmdProfile& profile, const LayerPlan& plan, int eye,
                   double blend_band_texels);
// Which plan layer (0 fovea, 1 middle, 2 outer) each kernel slot holds.
void slotLayers(const LayerPlan& plan, int eye, int layer_of_slot[3], int& slot_count);
void ucaTileSimd(const KernelParams& p, const TileJob& job);

}  // namespace qvr::detail

namespace qvr::detail {
// The Highway target the dispatcher picked on this CPU, e.g. "AVX3" or "AVX2".
const char* ucaSimdTarget();
}  // namespace qvr::detail
