// One frame of one side's work in a run, for the co-running measurement, the speed probe and
// the decode's cost where the headset decodes (calibration.h). Internal to the experiment part.
#pragma once

#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "qvr/codec/video_codec.h"
#include "qvr/compose/uca.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/session.h"
#include "qvr/sim/cost_fit.h"

#include "calibration_bench.h"

namespace qvr::experiment {

// The server's frame: the middle and outer layers of both eyes rendered with their holes, read
// back and each encoded in its own stream. The headset's: the fovea of both eyes rendered, the
// four streams' next frames decoded, UCA over the frame. At e1 = kCoRunE1Deg unless told; step
// k is the default motion's k-th refresh, with the first step's gaze throughout (so every layer
// keeps its size and any stream frame fits any step's plan).
class SideMix {
public:
    static constexpr double kE1Deg = kCoRunE1Deg;
    static constexpr int kStreamFrames = 24;  // the headset's streams, decoded round and round

    SideMix(Renderer& r, const HmdProfile& profile, const runtime::HeadsetInputs& inputs,
            const CodecConfig& codec, double e1_deg = kE1Deg)
        : m_r(r),
          m_profile(profile),
          m_inputs(inputs),
          m_codec(codec),
          m_e1_deg(e1_deg),
          m_planner(profile),
          m_compositor(profile, [] {
              ComposeOptions c;
              c.threads = 1;
              return c;
          }()) {}

    // The server's frame `step` (its encoders carry on from the frame before).
    Status server(int step);
    // The headset's frame `step`: its streams are the server's first kStreamFrames frames,
    // coded once (the first call), then decoded in order, key frame first, round and round.
    Status headset(int step);

    // Every decode's time from now on, against its canvas's pixels (nullptr: none).
    void recordDecodes(std::vector<CostSample>* sink) { m_decodes = sink; }
    // Fresh encoders and decoders, the streams from their first (key) frame: the frames after
    // are the same work as the last time after a restart (the speed probe's).
    void restart() {
        m_encoders = {};
        m_decoders = {};
        m_next_packet = 0;
    }

private:
    std::pair<Pose, LayerPlan> view(int step) const {
        const double t_ms = poseTimeMs(0) + 1000.0 / m_profile.refresh_hz * step;
        return {poseAt(m_inputs.traces.motion, t_ms),
                m_planner.plan(gazeAt(m_inputs.traces.gaze, poseTimeMs(0)), m_e1_deg)};
    }
    Renderer& m_r;
    const HmdProfile& m_profile;
    const runtime::HeadsetInputs& m_inputs;
    CodecConfig m_codec;
    double m_e1_deg;
    LayerPlanner m_planner;
    Compositor m_compositor;
    ImageRgba8 m_image;
    std::array<ImageRgba8, 2> m_display;
    std::array<std::unique_ptr<VideoEncoder>, 4> m_encoders;  // eye × {middle, outer}
    std::array<std::unique_ptr<VideoDecoder>, 4> m_decoders;
    std::array<std::vector<std::vector<uint8_t>>, 4> m_streams;
    std::array<double, 4> m_canvas_px{};  // each stream's canvas (its frames all share it)
    std::vector<CostSample>* m_decodes = nullptr;
    bool m_recording = false;
    int m_next_packet = 0;
};

// The speed probe (calibration.h SpeedProbe): the same headset and server frames every time,

// The speed probe (calibration.h SpeedProbe) on `mix`: the same headset and server frames every
// time, each after its key frame, their medians.
Expected<SpeedSample> probeSpeed(SideMix& mix);

}  // namespace qvr::experiment
