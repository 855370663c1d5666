// UCA — Unified Composition and ATW (paper §4.2, Eq. 3–4): the fovea, middle and outer layers
// of one frame are timewarped, lens-distorted and blended into the display image in a single
// filtering pass over 32×32 tiles; plus frame reuse and the two-pass reference it replaces.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <tbb/task_arena.h>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {

namespace detail {
struct CornerSample;  // uca.cpp: the map at a tile corner
}

// The three layer framebuffers of one eye. Texel (j, i) of a layer with rect R and scale s is
// centred on the full-resolution point (R.x0 + (j + ½)·s, R.y0 + (i + ½)·s); a layer the plan
// leaves out (0 pixels) has an empty image. Alpha is ignored: the display is opaque.
struct EyeLayerImages {
    ImageRgba8 fovea;
    ImageRgba8 middle;
    ImageRgba8 outer;
};

// Everything one rendered frame delivers to the compositor.
struct LayerFrame {
    uint64_t frame_index = 0;
    LayerPlan plan;
    Pose render_pose;  // the head pose the layers were rendered for
    std::array<EyeLayerImages, 2> eyes;
};

struct ComposeOptions {
    // The Highway kernel; false runs the scalar twin (same maths, one pixel at a time).
    bool simd = true;
    // Width of the Eq. 4 blend band inside each layer border, in texels of the coarser layer.
    double blend_band_texels = 2.0;
    // Honour the lens' per-channel chroma scales (costs three maps per pixel when they differ).
    bool chromatic_aberration = true;
    // Classify tiles (the fast path). False shades every tile as a border tile with every layer,
    // the check that classification never changes a pixel.
    bool classify_tiles = true;
    // Let single-layer tiles interpolate the map on an 8-pixel mesh wherever its error stays
    // within 1/16 texel (docs/UCA.md, "Mesh tiles"); false maps every pixel exactly.
    bool mesh_map = true;
    // Worker threads for the tile loop; 0 lets oneTBB use every core.
    int threads = 0;
};

// A 32×32 output tile, classified once per frame from a conservative bound on the eccentricity
// range it covers: nothing visible, one layer, or a border that blends two.
enum class TileKind : uint8_t { kEmpty, kSingle, kBorder };

struct TileStats {
    int64_t empty = 0;
    int64_t single = 0;
    int64_t border = 0;
    int64_t mesh = 0;  // single-layer tiles that used the interpolated map (a subset of single)
    int64_t total() const { return empty + single + border; }
};

struct ComposeReport {
    uint64_t frame_index = 0;  // the layer frame the display image was made from
    bool reused = false;       // true when the frame's layers were late and older ones re-warped
    int reused_in_a_row = 0;   // consecutive displays made from the same layer frame
    double warp_deg = 0.0;     // rotation between render and display pose
    TileStats tiles;           // both eyes
};

inline constexpr int kTilePx = 32;

// Checks that a frame's plan fits the profile and its images fit the plan.
Status validateFrame(const HmdProfile& profile, const LayerFrame& frame);

// One compositor per display loop: calls must not overlap (it keeps the newest frame and per-frame
// scratch); the tiles of one call run in parallel inside it.
class Compositor {
public:
    explicit Compositor(const HmdProfile& profile, ComposeOptions options = {});
    ~Compositor();
    Compositor(const Compositor&) = delete;
    Compositor& operator=(const Compositor&) = delete;

    const HmdProfile& profile() const { return m_profile; }
    const ComposeOptions& options() const { return m_options; }
    void setSimd(bool simd) { m_options.simd = simd; }

    // UCA: one pass from the frame's layers to the display image of both eyes for display_pose.
    // `out` is resized when needed; an invalid frame gives an error and leaves `out` untouched.
    Expected<ComposeReport> compose(const LayerFrame& frame, const Pose& display_pose,
                                    std::array<ImageRgba8, 2>& out);

    // The display loop's entry: `arrived` is this display's layer frame, or null when the remote
    // layers are late. A late frame re-warps the newest frame seen so far to display_pose (the
    // paper's filling-in of dropped frames) and says so in the report.
    Expected<ComposeReport> present(std::shared_ptr<const LayerFrame> arrived,
                                    const Pose& display_pose, std::array<ImageRgba8, 2>& out);
    const LayerFrame* newestFrame() const { return m_newest.get(); }

    // The two-pass reference: compose the layers into a full-resolution eye buffer per eye, then
    // timewarp that buffer. `eye_buffers`, when given, receives the composed buffers.
    Expected<ComposeReport> composeTwoPass(const LayerFrame& frame, const Pose& display_pose,
                                           std::array<ImageRgba8, 2>& out,
                                           std::array<ImageRgba8, 2>* eye_buffers = nullptr);

    // The tile classes of the last call for one eye (for composeTwoPass: its warp pass),
    // row-major over the tile grid.
    const std::vector<TileKind>& lastTileKinds(int eye) const { return m_tile_kinds[eye]; }
    int tileColumns() const;
    int tileRows() const;

private:
    HmdProfile m_profile;
    ComposeOptions m_options;
    std::unique_ptr<tbb::task_arena> m_arena;
    std::shared_ptr<const LayerFrame> m_newest;
    int m_reused_in_a_row = 0;
    std::array<std::vector<TileKind>, 2> m_tile_kinds;
    std::array<std::vector<uint8_t>, 2> m_tile_masks;
    std::array<ImageRgba8, 2> m_two_pass_buffers;
    // Per-eye scratch reused across frames, so a frame allocates nothing once sizes settle.
    std::array<std::vector<detail::CornerSample>, 2> m_lattices;
};

}  // namespace qvr
