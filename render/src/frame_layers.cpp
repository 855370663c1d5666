#include "qvr/render/frame_layers.h"

#include <fmt/format.h>

namespace qvr {

Expected<FrameLayers> renderFrameLayers(const Scene& scene, const FrameLayersPlan& plan,
                                        const FrameLayerSink& sink) {
    auto renderer = GlRenderer::create(plan.renderer);
    if (!renderer)
        return makeError(renderer.error());
    GlRenderer& gl = **renderer;
    if (Status s = gl.upload(scene); !s)
        return makeError(s.error());
    FrameLayers frame;
    frame.plan = plan;
    frame.layers_plan = LayerPlanner(plan.profile).plan(plan.gaze, plan.e1_deg);
    frame.scene = scene.name;
    frame.triangles = scene.triangleCount();
    frame.renderer = gl.name();
    ImageRgba8 image;
    auto render = [&](Eye eye, const std::string& layer, const LayerRect& rect,
                      const RenderView& view) -> Status {
        auto stats = gl.render(view, image);
        if (!stats)
            return makeError(fmt::format("{} {}: {}", eyeName(eye), layer, stats.error()));
        auto file = sink(eye, layer, image);
        if (!file)
            return makeError(file.error());
        frame.layers.push_back(
            {eye, layer, false, rect, view.width_px, view.height_px, *stats, *file});
        return {};
    };
    const HmdProfile& profile = plan.profile;
    for (Eye eye : {Eye::kLeft, Eye::kRight}) {
        for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter}) {
            const LayerRect& rect = layerOf(frame.layers_plan.eyes[static_cast<size_t>(eye)], kind);
            if (rect.empty()) {
                frame.layers.push_back({eye, layerName(kind), true, rect, 0, 0, {}, {}});
                continue;
            }
            const RenderView view = layerView(profile, plan.head, eye, rect, plan.camera);
            if (Status s = render(eye, layerName(kind), rect, view); !s)
                return makeError(s.error());
        }
        LayerRect full;
        full.rect = {0, 0, profile.width_px, profile.height_px};
        full.width_px = profile.width_px;
        full.height_px = profile.height_px;
        if (Status s =
                render(eye, "full", full, fullFrameView(profile, plan.head, eye, plan.camera));
            !s)
            return makeError(s.error());
    }
    return frame;
}

nlohmann::json frameLayersJson(const FrameLayers& f) {
    nlohmann::json j;
    j["scene"] = f.scene;
    j["profile"] = f.plan.profile.name;
    j["renderer"] = f.renderer;
    j["e1_deg"] = f.layers_plan.e1_deg;
    j["e2_deg"] = f.layers_plan.e2_deg;
    j["s1"] = f.layers_plan.s1;
    j["s2"] = f.layers_plan.s2;
    j["layers"] = nlohmann::json::array();
    for (const FrameLayer& l : f.layers) {
        if (l.empty)
            continue;
        const PixelRect& r = l.rect.rect;
        j["layers"].push_back({{"eye", eyeName(l.eye)},
                               {"layer", l.layer},
                               {"rect", {r.x0, r.y0, r.x1, r.y1}},
                               {"scale", l.rect.scale},
                               {"width_px", l.width_px},
                               {"height_px", l.height_px},
                               {"gpu_ms", l.stats.gpu_ms},
                               {"render_ms", l.stats.render_ms},
                               {"primitives", l.stats.primitives_generated},
                               {"file", l.file}});
    }
    return j;
}

std::string frameLayersText(const FrameLayers& f) {
    const HmdProfile& profile = f.plan.profile;
    const Pose& head = f.plan.head;
    const EulerDeg euler = eulerDegFromQuat(head.orientation);
    const LayerPlan& plan = f.layers_plan;
    std::string out =
        fmt::format("{}: {} triangles; {} ({}x{} per eye); renderer {}\n", f.scene, f.triangles,
                    profile.name, profile.width_px, profile.height_px, f.renderer);
    out += fmt::format(
        "head at ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.1f} pitch {:.1f} roll {:.1f} deg "
        "({}); gaze ({:.1f}, {:.1f}) deg\n",
        head.position_m.x, head.position_m.y, head.position_m.z, euler.yaw_deg, euler.pitch_deg,
        euler.roll_deg, f.plan.pose_source, f.plan.gaze.x_deg, f.plan.gaze.y_deg);
    out += fmt::format("e1 {:.2f}  e2* {:.2f}  s1 {:.2f}  s2 {:.2f}\n", plan.e1_deg, plan.e2_deg,
                       plan.s1, plan.s2);
    for (const FrameLayer& l : f.layers) {
        const PixelRect& r = l.rect.rect;
        out +=
            l.empty
                ? fmt::format("  {:<5} {:<6} empty at this e1, no file\n", eyeName(l.eye), l.layer)
                : fmt::format(
                      "  {:<5} {:<6} [{:4},{:4})x[{:4},{:4}) scale {:5.2f} {:5}x{:<5} "
                      "{:7.2f} ms {:8} tris  {}\n",
                      eyeName(l.eye), l.layer, r.x0, r.x1, r.y0, r.y1, l.rect.scale, l.width_px,
                      l.height_px, l.stats.render_ms, l.stats.primitives_generated, l.file);
    }
    return out;
}

}  // namespace qvr
