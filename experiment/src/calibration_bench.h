// What the calibration's micro-benchmarks run on (calibration.cpp's steps): the scene and the
// renderer, the poses, the codec, and the samples they take. Internal to the experiment part.
#pragma once

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "qvr/codec/video_codec.h"
#include "qvr/compose/uca.h"
#include "qvr/core/expected.h"
#include "qvr/experiment/calibration.h"
#include "qvr/experiment/calibration_fit.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/draw_list.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/workload_probe.h"

namespace qvr::experiment {

using CalibrationClock = std::chrono::steady_clock;

inline double msSince(CalibrationClock::time_point t0) {
    return std::chrono::duration<double, std::milli>(CalibrationClock::now() - t0).count();
}

// The calibration's view k: the default head motion and gaze over the span a default run covers
// (150 frames at 90 Hz, 1.7 s). In an enclosed level the BVH counts almost the whole scene in
// every view, so what a layer costs depends on what it sees at its level of detail, which the
// cost's features do not capture: other seconds of the motion mispredict the room's periphery
// layers by 2x (docs/MODEL.md §9).
inline double poseTimeMs(int k) {
    return 50.0 + 290.0 * k;
}

// A pass's shaded fragments for its cost sample; −1 (not counted) where the driver has no
// pipeline statistics.
inline double fragmentsOf(const RenderStats& st) {
    return st.statistics ? double(st.fragment_invocations) : -1.0;
}

struct CalibrationPose {
    Pose head;
    Gaze gaze;
};

// Everything the steps share, made once by makeCalibrationBench; its address does not change
// (the planner, the workload probe and the compositor hold the profile).
struct CalibrationBench {
    CalibrateOptions options;
    HmdProfile profile;
    runtime::HeadsetInputs inputs;
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<LayerPlanner> planner;
    // The triangles a layer draws (render/renderer.h layerTriangles): the draw list as the
    // renderer builds it, at the same level of detail.
    std::shared_ptr<DrawList> draw_list;
    // LIWC's ring counts as the runtime makes them (HeadsetConfig::cluster_ring_counts).
    std::unique_ptr<runtime::WorkloadProbe> probe;
    std::unique_ptr<Compositor> compositor;  // one thread, as the headset's
    CodecConfig codec;
    // The server's periphery layers with their holes (RenderServerConfig::holes), as `qvr run`'s
    // server draws them.
    LayerHoles holes{.enabled = true};
    double eye_px = 0.0;                 // one eye's display pixels
    std::vector<CalibrationPose> poses;  // the views the render samples are taken at
    std::vector<double> e1s;             // the e1 the layers are sampled at
    int codec_frames = 0;                // the motion frames the codec pass codes
    ImageRgba8 image;                    // scratch: one layer
    std::array<ImageRgba8, 2> display;   // scratch: UCA's output

    Renderer& r() { return *renderer; }
    double frameMs() const { return 1000.0 / profile.refresh_hz; }
    double drawnTriangles(const LayerPlan& plan, const Pose& head, int eye, LayerKind kind) const;
    void log(const std::string& line) const;
};

// The scene loaded and uploaded, the thread pinned to options.core (unpinned, with a warning,
// where it cannot be), the poses: the default motion's first seconds, the seeded gaze model.
// These are not a run's frames: no pipeline, no network, each part timed alone.
Expected<std::unique_ptr<CalibrationBench>> makeCalibrationBench(const CalibrateOptions& options);

// The steps, in the order runCalibration takes them; each appends to `samples`.
// The decision's ring counts, five times at every pose.
void measureDecision(CalibrationBench& bench, CalibrationSamples& samples);
// A frame's plan at three e1 at every pose.
void measurePlan(CalibrationBench& bench, CalibrationSamples& samples);
// One pass of each layer kind, untimed: llvmpipe compiles its shaders on first use.
Status warmUpRenderer(CalibrationBench& bench);
// Short sequences of consecutive frames at every pose and e1: fovea, periphery layers, UCA.
Status measureLayerSequences(CalibrationBench& bench, CalibrationSamples& samples);
// The full frame at every pose: local's render, remote's server layer, UCA over it and the
// display video's copy.
Status measureFullFrames(CalibrationBench& bench, CalibrationSamples& samples);
// The codec over a run's span at every e1: encode times, bits, key frames, padding; what each
// e1 spent (Calibration::codec_by_e1) returned.
Expected<nlohmann::json> measureLayerCodec(CalibrationBench& bench, CalibrationSamples& samples);
// remote's whole frame through its own encoders: its bits and encode times.
Status measureWholeFrameCodec(CalibrationBench& bench, CalibrationSamples& samples);
// The decode where the headset decodes: inside headset frames.
Status measureDecodes(CalibrationBench& bench, CalibrationSamples& samples);
// Both sides' co-running slowdowns (corun_measure.cpp).
Status measureCoRun(CalibrationBench& bench, Calibration& cal);

// The canvas the runtime's encoders use (codec/video_codec.h CodecConfig), as the costs
// replay it.
void copyCanvasPolicy(const CodecConfig& codec, RuntimeCosts& costs);

}  // namespace qvr::experiment
