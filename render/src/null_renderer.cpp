// The renderer without a device, what tests of frame logic use when they need the counts of a
// rendering but not its pixels; and the device-independent pieces every renderer shares.
#include <algorithm>
#include <vector>

#include "qvr/render/draw_list.h"
#include "qvr/render/renderer.h"

namespace qvr {

double layerHoleDeg(const HmdProfile& profile, const LayerPlan& plan, Eye eye, LayerKind kind,
                    const LayerHoles& holes) {
    if (!holes.enabled || kind == LayerKind::kFovea)
        return 0.0;
    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
    const LayerRect& self = layerOf(layers, kind);
    // The finer layer the hole is taken from must be there.
    const LayerRect& finer = kind == LayerKind::kMiddle ? layers.fovea : layers.middle;
    if (self.empty() || finer.empty())
        return 0.0;
    const double radius_deg = kind == LayerKind::kMiddle ? plan.e1_deg : plan.e2_deg;
    const double band_deg =
        (holes.band_texels + holes.margin_texels) * self.scale * profile.pixelAngleDeg();
    return std::max(0.0, radius_deg - band_deg);
}

Expected<RenderStats> renderLayer(Renderer& renderer, const HmdProfile& profile,
                                  const LayerPlan& plan, const Pose& head, Eye eye, LayerKind kind,
                                  ImageRgba8& out, const CameraOptions& options,
                                  const LayerHoles& holes) {
    const LayerRect& layer = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
    if (layer.empty()) {
        out.resize(0, 0);
        return RenderStats{};
    }
    RenderView view = layerView(profile, head, eye, layer, options);
    setSkipCone(view, profile, head, eye, plan.gaze, layerHoleDeg(profile, plan, eye, kind, holes),
                options);
    return renderer.render(view, out);
}

uint64_t layerTriangles(const DrawList& list, const HmdProfile& profile, const LayerPlan& plan,
                        const Pose& head, Eye eye, LayerKind kind, float lod_error_px,
                        const CameraOptions& options, const LayerHoles& holes) {
    const LayerRect& layer = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
    if (layer.empty())
        return 0;
    RenderView view = layerView(profile, head, eye, layer, options);
    setSkipCone(view, profile, head, eye, plan.gaze, layerHoleDeg(profile, plan, eye, kind, holes),
                options);
    return selectDraws(list, view, lod_error_px).triangles;
}

namespace {

class NullRenderer final : public Renderer {
public:
    std::string name() const override { return "null"; }

    Status upload(const Scene& scene) override {
        if (Status s = checkDrawable(scene); !s)
            return s;
        m_draw_list = buildDrawList(scene);
        return Status::success();
    }

    Expected<RenderStats> render(const RenderView& view, ImageRgba8& out) override {
        if (out.width() != view.width_px || out.height() != view.height_px)
            out.resize(view.width_px, view.height_px);
        uint8_t* p = out.data();
        const size_t n = static_cast<size_t>(view.width_px) * static_cast<size_t>(view.height_px);
        for (size_t i = 0; i < n; ++i, p += 4) {
            for (int c = 0; c < 4; ++c)
                p[c] = kClearRgba[c];
        }
        const DrawSelection sel = selectDraws(m_draw_list, view);
        RenderStats stats;
        stats.primitives_generated = sel.triangles;
        stats.clusters_drawn = sel.clusters_drawn;
        stats.clusters_culled = sel.clusters_culled;
        stats.clusters_skipped = sel.clusters_skipped;
        stats.draw_calls = static_cast<uint32_t>(sel.draws.size());
        return stats;
    }

private:
    DrawList m_draw_list;
};

}  // namespace

std::unique_ptr<Renderer> makeNullRenderer() {
    return std::make_unique<NullRenderer>();
}

}  // namespace qvr
