// The calibration's bench (calibration_bench.h) and its first steps: the decision, the plan,
// the renderer's warm-up.
#include "calibration_bench.h"

#include <cstdio>

#include <fmt/format.h>

#include "qvr/render/gl_renderer.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/render_server.h"

namespace qvr::experiment {

double CalibrationBench::drawnTriangles(const LayerPlan& plan, const Pose& head, int eye,
                                        LayerKind kind) const {
    return double(layerTriangles(*draw_list, profile, plan, head, static_cast<Eye>(eye), kind,
                                 options.lod_px, CameraOptions{},
                                 kind == LayerKind::kFovea ? LayerHoles{} : holes));
}

void CalibrationBench::log(const std::string& line) const {
    if (options.verbose) {
        std::fputs(line.c_str(), stdout);
        std::fflush(stdout);
    }
}

namespace {

// The renderer, the planner, the draw list, the workload probe and the compositor on the loaded
// scene.
Status setUpRendering(CalibrationBench& b) {
    GlRendererOptions gl;
    gl.lod_error_px = b.options.lod_px;
    auto renderer = runtime::glRendererFactory(gl)();
    if (!renderer)
        return makeError(renderer.error());
    b.renderer = std::move(*renderer);
    if (auto st = b.renderer->upload(*b.inputs.scene); !st)
        return makeError(st.error());
    b.planner = std::make_unique<LayerPlanner>(b.profile);
    b.draw_list = std::make_shared<DrawList>(buildDrawList(*b.inputs.scene));
    if (b.options.lod_px > 0.0f)
        buildLods(*b.draw_list, *b.inputs.scene);
    b.probe = std::make_unique<runtime::WorkloadProbe>(b.profile, b.inputs.bvh);
    b.probe->useClusters(b.draw_list, b.options.lod_px);
    ComposeOptions compose;
    compose.threads = 1;
    b.compositor = std::make_unique<Compositor>(b.profile, compose);
    return {};
}

}  // namespace

Expected<std::unique_ptr<CalibrationBench>> makeCalibrationBench(const CalibrateOptions& o) {
    auto profile = runtime::runtimeProfileByName(o.profile);
    if (!profile)
        return makeError("--profile: " + profile.error());
    if (o.core >= 0) {
        if (auto st = runtime::pinCurrentThread(o.core); !st)
            std::fprintf(stderr, "qvr calibrate: %s (running unpinned)\n", st.error().c_str());
    }
    auto inputs =
        runtime::loadHeadsetInputs(o.scene, "default", "model", profile->refresh_hz, 400, 7);
    if (!inputs)
        return makeError(inputs.error());
    auto bench = std::make_unique<CalibrationBench>();
    CalibrationBench& b = *bench;
    b.options = o;
    b.profile = *profile;
    b.inputs = std::move(*inputs);
    if (auto st = setUpRendering(b); !st)
        return makeError(st.error());
    b.codec.backend = o.codec;
    b.eye_px = double(b.profile.width_px) * b.profile.height_px;
    const int n_poses = o.quick ? 3 : 6;
    for (int k = 0; k < n_poses; ++k) {
        const double t_ms = poseTimeMs(k);
        b.poses.push_back(
            {poseAt(b.inputs.traces.motion, t_ms), gazeAt(b.inputs.traces.gaze, t_ms)});
    }
    b.e1s = o.quick ? std::vector<double>{3, 8, 15, 30}
                    : std::vector<double>{2, 4, 6, 9, 13, 18, 25, 35};
    b.codec_frames = o.quick ? 40 : 120;
    return bench;
}

void measureDecision(CalibrationBench& b, CalibrationSamples& s) {
    for (const CalibrationPose& p : b.poses)
        for (int rep = 0; rep < 5; ++rep) {
            const auto t0 = CalibrationClock::now();
            const WorkloadFrame wf = b.probe->frame(0, 0.0, p.head, p.gaze);
            s.decision.push_back({msSince(t0), 0.0, 0.0});
            (void)wf;
        }
    b.log(fmt::format("  decision: {} samples\n", s.decision.size()));
}

void measurePlan(CalibrationBench& b, CalibrationSamples& s) {
    for (const CalibrationPose& p : b.poses)
        for (double e1 : {3.0, 8.0, 15.0}) {
            const auto t0 = CalibrationClock::now();
            const LayerPlan plan = b.planner->plan(p.gaze, e1);
            s.plan_ms.push_back(msSince(t0));
            (void)plan;
        }
}

Status warmUpRenderer(CalibrationBench& b) {
    const LayerPlan plan = b.planner->plan(b.poses[0].gaze, 10.0);
    for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter})
        if (auto st =
                renderLayer(b.r(), b.profile, plan, b.poses[0].head, Eye::kLeft, kind, b.image);
            !st)
            return makeError("render: " + st.error());
    return {};
}

}  // namespace qvr::experiment
