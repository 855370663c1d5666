// The renderer without a device, what tests of frame logic use when they need the counts of a
// rendering but not its pixels; and the device-independent pieces every renderer shares.
#include <vector>

#include "qvr/render/renderer.h"

namespace qvr {

BatchSelection selectBatches(const std::vector<SceneBatch>& batches, const RenderView& view) {
    BatchSelection s;
    const FrustumPlanes planes = frustumPlanes(view.viewProjection());
    s.batches.reserve(batches.size());
    for (size_t i = 0; i < batches.size(); ++i) {
        const SceneBatch& b = batches[i];
        if (b.index_count < 3)
            continue;
        if (!boxMayBeVisible(planes, b.bounds)) {
            ++s.culled;
            continue;
        }
        s.batches.push_back(static_cast<uint32_t>(i));
        s.triangles += b.index_count / 3;
    }
    return s;
}

Expected<RenderStats> renderLayer(Renderer& renderer, const HmdProfile& profile,
                                  const LayerPlan& plan, const Pose& head, Eye eye, LayerKind kind,
                                  ImageRgba8& out, const CameraOptions& options) {
    const LayerRect& layer = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
    if (layer.empty()) {
        out.resize(0, 0);
        return RenderStats{};
    }
    return renderer.render(layerView(profile, head, eye, layer, options), out);
}

namespace {

class NullRenderer final : public Renderer {
public:
    std::string name() const override { return "null"; }

    Status upload(const Scene& scene) override {
        m_batches = scene.batches;
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
        const BatchSelection sel = selectBatches(m_batches, view);
        RenderStats stats;
        stats.primitives_generated = sel.triangles;
        stats.batches_drawn = static_cast<uint32_t>(sel.batches.size());
        stats.batches_culled = sel.culled;
        return stats;
    }

private:
    std::vector<SceneBatch> m_batches;
};

}  // namespace

std::unique_ptr<Renderer> makeNullRenderer() {
    return std::make_unique<NullRenderer>();
}

}  // namespace qvr
