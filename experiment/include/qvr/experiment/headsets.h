// Several headsets on one render server (`qvr run --headsets N`): each headset's workload (its
// head motion and gaze), what each one measured, and the aggregate a deployment is judged on —
// Jain's fairness index over the headsets' frame rates and the server's time per headset-frame.
// Pure functions: the processes that produce the numbers are design_runs.h's.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/runtime/render_server.h"
#include "qvr/runtime/telemetry.h"

namespace qvr::experiment {

inline constexpr int kMinHeadsets = 1;
inline constexpr int kMaxHeadsets = 16;

// What one headset sees: its head motion ("default", a .bvh, a pose CSV, "still") and its gaze
// ("model" with its seed, "center", a CSV).
struct HeadsetWorkload {
    std::string motion;
    std::string gaze;
    uint64_t seed = 1;
    double ahead_ms = 0.0;  // plays its motion and gaze this far ahead (playAhead)
    bool operator==(const HeadsetWorkload&) const = default;
};

// The head-motion recordings the default set cycles through: the CMU motion-capture clips of
// Debian's assimp-testmodels (the first is runtime's default, defaultBvhPath()).
std::vector<std::string> defaultMotionRecordings();

// The workloads of `headsets` headsets. Headset 0 always has the plan's own (motion, gaze,
// seed), so one headset runs what `qvr run` always ran. Identical: every headset the same. Else,
// with the default motion, headset k takes recording k of `recordings` (cyclically) and the gaze
// seed seed + k; with any other motion, every headset that motion and its own gaze seed. Headset
// k plays k × offset_ms ahead (qvr run --headset-offset-ms).
std::vector<HeadsetWorkload> headsetWorkloads(int headsets, const std::string& motion,
                                              const std::string& gaze, uint64_t seed,
                                              bool identical,
                                              const std::vector<std::string>& recordings,
                                              double offset_ms = 0.0);

// Jain's fairness index (Σx)² / (n·Σx²): 1 when every value is equal, 1/n when one takes all.
// 1 for no values or all zero; negative values are taken as 0.
double jainFairness(std::span<const double> values);

// One headset's session as it measured it.
struct HeadsetOutcome {
    int index = 0;
    HeadsetWorkload workload;
    runtime::DesignSummary summary;
    std::string error;  // why it has no summary (empty: it has one)
};

// The server's work over a span of time: its frames (one per headset-frame it served) and their
// render, readback and encode time.
struct ServerShare {
    int64_t frames = 0;
    double busy_ms_total = 0.0;
    double msPerFrame() const { return frames > 0 ? busy_ms_total / double(frames) : 0.0; }
};
// The server frames that started within [start_ns, end_ns] (the server's stamps, CLOCK_MONOTONIC
// as the headsets' steady clock), each counted for the sum over its layers of render start to
// encode end (as serverBusyPerDesign counts it).
ServerShare serverShare(const std::vector<runtime::ServerFrameStamps>& stamps, int64_t start_ns,
                        int64_t end_ns);

// One design's run with every headset.
struct HeadsetsResult {
    std::string design;
    std::vector<HeadsetOutcome> headsets;  // by index
    double jain_fairness_fps = 1.0;        // over the headsets with a summary
    std::optional<double> server_ms_per_headset_frame;
    double fps_mean = 0.0;  // over the headsets with a summary
    double fps_min = 0.0;
};
HeadsetsResult aggregateHeadsets(const std::string& design, std::vector<HeadsetOutcome> headsets,
                                 const std::optional<ServerShare>& server);

// A list entry of summary.json's "headsets", and one design's block (the list, the index, the
// server time).
nlohmann::json headsetJson(const HeadsetOutcome& headset);
nlohmann::json headsetsJson(const HeadsetsResult& result);

// The design whose headsets summary.json puts at its top level: qvr when run, else the last.
const HeadsetsResult* headlineHeadsets(const std::vector<HeadsetsResult>& by_design);

}  // namespace qvr::experiment
