// The renderer seam (paper §3.2: the headset renders the fovea layer, the server the middle and
// outer layers, each into its own framebuffer): upload a scene once, then render views of it.
// A null implementation serves tests that need no pixels; the OpenGL one lives in gl_renderer.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"
#include "qvr/render/camera.h"
#include "qvr/render/draw_list.h"
#include "qvr/scene/scene.h"

namespace qvr {

struct RenderStats {
    // Time the GPU spent on the draws (GL_TIME_ELAPSED); on llvmpipe this is CPU rasterizer time.
    double gpu_ms = 0.0;
    // Wall-clock time from the first command to the finished frame, before the read-back.
    double render_ms = 0.0;
    // Wall-clock time of copying the framebuffer into the image.
    double readback_ms = 0.0;
    // Triangles submitted after the CPU's per-cluster frustum culling (GL_PRIMITIVES_GENERATED).
    uint64_t primitives_generated = 0;
    // Triangles that reached the clipper and that left it (ARB_pipeline_statistics_query);
    // 0 when the driver does not offer the statistics.
    uint64_t clipping_input_primitives = 0;
    uint64_t clipping_output_primitives = 0;
    // Fragment shader invocations (ARB_pipeline_statistics_query; 0 without it): the pixels
    // shaded, counting every layer of overdraw the depth test did not reject early.
    uint64_t fragment_invocations = 0;
    bool statistics = false;      // the three counts above were taken (0 then means none)
    uint32_t clusters_drawn = 0;  // spatial clusters of the draw list (draw_list.h)
    uint32_t clusters_culled = 0;
    uint32_t clusters_skipped = 0;  // inside the view's hole
    uint32_t draw_calls = 0;
};

class Renderer {
public:
    virtual ~Renderer() = default;

    virtual std::string name() const = 0;
    // Copies the scene's geometry and textures to the device; replaces any earlier scene.
    virtual Status upload(const Scene& scene) = 0;
    // Renders the uploaded scene as `view` sees it into `out`, resized to the view's size, row 0
    // at the top, alpha 255. Errors only for a failing device, never for an empty view.
    virtual Expected<RenderStats> render(const RenderView& view, ImageRgba8& out) = 0;
};

// Holes in the periphery layers (docs/RENDER.md "Holes"): the middle layer need not draw what
// the compositor takes from the fovea alone, nor the outer layer what it takes from the middle
// alone. The compositor blends two layers in a band of band_texels texels of the coarser layer
// inside the finer layer's edge (ComposeOptions::blend_band_texels); the hole stops
// margin_texels more texels short of that band.
struct LayerHoles {
    bool enabled = false;
    double band_texels = 2.0;
    double margin_texels = 1.0;
};

// The hole's radius for a layer of the plan (0: none): the fovea's e1 for the middle layer, e2
// for the outer one, less the blend band and the margin, in the coarser layer's texels.
double layerHoleDeg(const HmdProfile& profile, const LayerPlan& plan, Eye eye, LayerKind kind,
                    const LayerHoles& holes);

// One layer of a layer plan for one eye: its sub-frustum into an image of the layer's own size
// (paper §3.2). An empty layer (e.g. no middle layer when the fovea covers the field) gives an
// empty image and zero stats.
Expected<RenderStats> renderLayer(Renderer& renderer, const HmdProfile& profile,
                                  const LayerPlan& plan, const Pose& head, Eye eye, LayerKind kind,
                                  ImageRgba8& out, const CameraOptions& options = {},
                                  const LayerHoles& holes = {});

// The triangles renderLayer() submits for this layer through a renderer at lod_error_px (what
// the OpenGL renderer's primitives-generated query counts), without a device: the draw list's
// selection for the layer's view, level of detail and hole. `list` is buildDrawList() of the
// uploaded scene, with buildLods() when lod_error_px > 0, as the renderer makes it. The
// calibration fits render costs on it and the runtime model charges it (docs/MODEL.md §9).
uint64_t layerTriangles(const DrawList& list, const HmdProfile& profile, const LayerPlan& plan,
                        const Pose& head, Eye eye, LayerKind kind, float lod_error_px,
                        const CameraOptions& options = {}, const LayerHoles& holes = {});

// Renders nothing: fills the image with the clear colour and reports the triangles of the
// clusters that survive frustum culling — the same count the OpenGL renderer submits.
std::unique_ptr<Renderer> makeNullRenderer();

// The colour of pixels no triangle covers: a dark blue that no test texture uses.
inline constexpr uint8_t kClearRgba[4] = {20, 24, 40, 255};

}  // namespace qvr
