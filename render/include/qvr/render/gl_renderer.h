// The OpenGL 4.5 core renderer, headless through EGL's surfaceless platform (Mesa llvmpipe on a
// CPU, a vendor driver on a GPU): textured, lightmapped triangles into an off-screen framebuffer
// per layer size, with GPU time and primitive counts from GL queries.
#pragma once

#include <memory>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/render/renderer.h"

namespace qvr {

struct GlRendererOptions {
    // Multiplies the lightmap before shading; Quake III levels are authored for an overbright
    // factor of 2 (r_mapOverBrightBits 1 on a gamma-ramped display).
    float lightmap_gain = 1.0f;
    // Samples per pixel (1 = no multisampling). 4 smooths geometry edges, which the periphery's
    // video encoder would otherwise spend bits on; llvmpipe pays for it in fill time.
    int msaa_samples = 1;
    // Level of detail (draw_list.h): each cluster is drawn at the coarsest vertex-clustering
    // level that moves no vertex by more than this many of the view's pixels. 0 draws the
    // scene's own triangles everywhere. The bound is per view, so a layer rendered at scale s
    // may use cells s times larger than a full-resolution view of the same place.
    float lod_error_px = 0.0f;
};

struct GlInfo {
    std::string egl_platform;  // "surfaceless" or "default"
    std::string vendor;
    std::string renderer;
    std::string version;
    bool pipeline_statistics = false;  // GL_ARB_pipeline_statistics_query
    int max_framebuffer_px = 0;        // the smaller of the renderbuffer and viewport limits
    int max_samples = 1;               // GL_MAX_SAMPLES
};

class GlRenderer final : public Renderer {
public:
    // Creates an EGL display, a core 4.5 context and the shaders, and makes the context current
    // on the calling thread; the renderer must then be used from that thread only. Errors (no
    // EGL, no GL 4.5) are reported with what to install, never a crash.
    static Expected<std::unique_ptr<GlRenderer>> create(const GlRendererOptions& options = {});
    ~GlRenderer() override;
    GlRenderer(const GlRenderer&) = delete;
    GlRenderer& operator=(const GlRenderer&) = delete;

    const GlInfo& info() const;
    std::string name() const override;
    Status upload(const Scene& scene) override;
    Expected<RenderStats> render(const RenderView& view, ImageRgba8& out) override;

    // The triangles of the uploaded scene (all batches, no CPU culling) that a view processes:
    // those with some part inside the closed clip volume −w ≤ x, y, z ≤ w. A geometry shader
    // clips each triangle against the six planes and emits it when a polygon survives; a
    // GL_PRIMITIVES_GENERATED query counts what it emitted, with rasterization discarded. This is
    // the GL side of the check of the scene part's CPU count (TriangleBvh, docs/RENDER.md).
    Expected<uint64_t> countTrianglesInFrustum(const RenderView& view);

    struct Impl;

private:
    explicit GlRenderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

}  // namespace qvr
