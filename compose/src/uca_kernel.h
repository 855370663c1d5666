// The per-tile UCA kernel (paper §4.2, Eq. 4) in two builds that must agree: a Highway kernel
// that maps and filters a vector of pixels at a time, and its scalar twin. Private to compose.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

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
    // once and read by someone else, so it need not displace the layers from the caches. The
    // caller fences them (ucaFenceStreams) before it reports the tile done.
    bool stream = false;
    // Let a single-layer or border tile interpolate its map on the 8-pixel mesh where the
    // mesh's error is within the bounds below (MeshLattice); false maps every pixel exactly.
    bool mesh = false;
};

// Mesh tiles (docs/UCA.md, "Mesh tiles"): the exact map at the nodes (x0 + 8i, y0 + 8j) of a
// tile and bilinear interpolation in between — of the layer's texel coordinates in a
// single-layer tile, of the rendered-image point in a border tile (whose eccentricity is then
// that of the interpolated point, meshEccentricityCos). A tile qualifies per frame when
//  * at every cell centre and edge midpoint (the 9×9 lattice at a 4-pixel step, nodes at even
//    indices) the exact map is within kMeshBoundTexels of the interpolation, in texels of the
//    finest layer the tile samples;
//  * every lattice point is at least kMeshMarginPx inside the rendered image (no pixel of the
//    tile is invalid), and in a single-layer tile its texel coordinate lies in
//    [kMeshTexelMargin, size − 1 − kMeshTexelMargin] (the interpolated coordinates need no
//    clamp).
// Both kernels evaluate the lattice with the same float arithmetic and decide alike.
inline constexpr int kMeshStepPx = 8;
static_assert(kTilePx % kMeshStepPx == 0);
inline constexpr int kMeshCells = kTilePx / kMeshStepPx;
inline constexpr int kMeshLatticeSide = 2 * kMeshCells + 1;
inline constexpr int kMeshLatticePoints = kMeshLatticeSide * kMeshLatticeSide;
// Storage rounded up to whole vectors of the widest target.
inline constexpr int kMeshLatticeStorage = 96;
inline constexpr float kMeshBoundTexels = 1.0f / 16.0f;
inline constexpr float kMeshMarginPx = 1.0f;
inline constexpr float kMeshTexelMargin = 1.0f / 64.0f;

// The lattice of one tile, row-major (point (i, j) is display pixel (x0 + 4i, y0 + 4j)): the
// exact rendered-image point — (0, 0) when invalid (off the image, behind the eye), which fails
// the margin — its texel coordinate in a single-layer tile's layer, lx = px·inv_scale +
// offset_x (one fused multiply-add).
struct MeshLattice {
    // The vector kernel reads neighbours up to a lattice row and one point before and after.
    float head[16];
    float px[kMeshLatticeStorage];
    float py[kMeshLatticeStorage];
    float lx[kMeshLatticeStorage];
    float ly[kMeshLatticeStorage];
    float tail[16];
};

// Which of a lattice's values a tile interpolates and how closely they must follow the map.
struct MeshPlan {
    bool border = false;  // interpolate px, py (else lx, ly of `layer`)
    int layer = 0;        // the single-layer tile's slot
    float bound_xy = 0;   // in the units of the interpolated coordinates
    // False for a border with a full-resolution layer (the fovea's edge): there the exact map
    // keeps the sharp layer's positions exact (docs/UCA.md, "Mesh tiles").
    bool usable = true;
};

inline MeshPlan meshPlan(const KernelParams& p, uint8_t slot_mask) {
    MeshPlan plan;
    plan.border = (slot_mask & (slot_mask - 1)) != 0;
    if (!plan.border) {
        plan.layer = slot_mask == 1 ? 0 : (slot_mask == 2 ? 1 : 2);
        plan.bound_xy = kMeshBoundTexels;
        return plan;
    }
    float inv = 0.0f;
    for (int k = 0; k < p.slot_count; ++k) {
        if ((slot_mask & (1u << k)) != 0)
            inv = inv > p.slots[k].inv_scale ? inv : p.slots[k].inv_scale;
    }
    plan.bound_xy = kMeshBoundTexels / inv;
    plan.usable = inv < 1.0f;
    return plan;
}

// The scalar statement of the test; the vector kernel evaluates the same comparisons on the
// same floats a vector of lattice points at a time and must agree.
inline bool meshAcceptable(const MeshLattice& m, const KernelParams& p, const MeshPlan& plan) {
    const KernelLayer& l = p.slots[plan.layer];
    const float max_lx = static_cast<float>(l.width - 1) - kMeshTexelMargin;
    const float max_ly = static_cast<float>(l.height - 1) - kMeshTexelMargin;
    for (int k = 0; k < kMeshLatticePoints; ++k) {
        // Written so that a NaN fails too.
        if (!(m.px[k] >= kMeshMarginPx && m.px[k] <= p.width - kMeshMarginPx &&
              m.py[k] >= kMeshMarginPx && m.py[k] <= p.height - kMeshMarginPx)) {
            return false;
        }
        if (!plan.border && !(m.lx[k] >= kMeshTexelMargin && m.lx[k] <= max_lx &&
                              m.ly[k] >= kMeshTexelMargin && m.ly[k] <= max_ly)) {
            return false;
        }
    }
    constexpr int n = kMeshLatticeSide;
    // Interpolation at a midpoint from the two (edge) or four (centre) nodes around it.
    auto within = [&](const float* v, int j, int i, float bound) {
        float interp;
        if ((i & 1) != 0 && (j & 1) != 0) {
            interp = 0.25f * ((v[(j - 1) * n + i - 1] + v[(j - 1) * n + i + 1]) +
                              (v[(j + 1) * n + i - 1] + v[(j + 1) * n + i + 1]));
        } else if ((i & 1) != 0) {
            interp = 0.5f * (v[j * n + i - 1] + v[j * n + i + 1]);
        } else {
            interp = 0.5f * (v[(j - 1) * n + i] + v[(j + 1) * n + i]);
        }
        const float err = v[j * n + i] - interp;
        return err <= bound && err >= -bound;
    };
    const float* x = plan.border ? m.px : m.lx;
    const float* y = plan.border ? m.py : m.ly;
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            if (((i | j) & 1) == 0)
                continue;  // a node
            if (!within(x, j, i, plan.bound_xy) || !within(y, j, i, plan.bound_xy))
                return false;
        }
    }
    return true;
}

inline constexpr uint32_t kOpaqueBlack = 0xFF000000u;

// Biased channels (docs/UCA.md): a texel byte c is filtered as the float 2^15 + ½ + c, whose bit
// pattern is kTexelBiasBits | c << 8 — no int → float conversion — and whose 1/256 resolution
// is kept by every lerp. The ½ rides along (lerps of values that share it keep it), so bits
// 8–15 of a filtered value are already its rounded byte.
inline constexpr float kTexelBias = 32768.5f;
inline constexpr uint32_t kTexelBiasBits = 0x47000080u;

// Both return true when the tile used the interpolated (mesh) map.
bool ucaTileScalar(const KernelParams& p, const TileJob& job);
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
bool ucaTileSimd(const KernelParams& p, const TileJob& job);
// For tests: the kernel's compiled targets this CPU supports, their names, and restricting the
// dispatch to some of them (0: back to everything the CPU supports).
std::vector<int64_t> ucaAvailableTargets();
const char* ucaTargetName(int64_t target);
void ucaSetTargetsForTest(int64_t targets);
// Orders the calling thread's streaming stores before its later stores (sfence).
void ucaFenceStreams();

}  // namespace qvr::detail

namespace qvr::detail {
// The Highway target the dispatcher picked on this CPU, e.g. "AVX3" or "AVX2".
const char* ucaSimdTarget();
}  // namespace qvr::detail
