// A run's designs predicted by the simulators: the runtime pipeline model with this machine's
// calibration (sim/runtime_model.h), again with each design's costs at the machine's speed around
// it, and the paper's model on its modelled hardware; and each prediction's error against what
// was measured.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "qvr/core/design.h"
#include "qvr/core/pose.h"
#include "qvr/experiment/design_runs.h"
#include "qvr/render/draw_list.h"
#include "qvr/sim/hardware.h"
#include "qvr/sim/runtime_model.h"
#include "qvr/workload/workload.h"

namespace qvr::experiment {

// The metrics a prediction is compared on, in the order summary.json and the report list them.
enum class Metric { kFps, kMtpMean, kMtpP99, kBytes, kE1, kHeadsetBusy, kServerBusy };
inline constexpr std::array<Metric, 7> kComparedMetrics = {
    Metric::kFps, Metric::kMtpMean,     Metric::kMtpP99,    Metric::kBytes,
    Metric::kE1,  Metric::kHeadsetBusy, Metric::kServerBusy};
// Its key in summary.json ("fps_mean", …).
const char* metricKey(Metric metric);

// One design's headline metrics, measured or predicted. The two sides' own costs (the headset's
// busy time per frame after the start-up, the server's render and encode per served frame) tell
// which side an error is on; the paper's model predicts neither.
struct DesignMetrics {
    double fps_mean = 0.0;
    double mtp_ms_mean = 0.0;
    double mtp_ms_p99 = 0.0;
    double bytes_per_frame_mean = 0.0;
    double e1_deg_mean = 0.0;
    std::optional<double> headset_busy_ms_mean;
    std::optional<double> server_busy_ms_mean;
    std::optional<double> value(Metric metric) const;
};

// What a design's run measured, as a prediction is compared on it; server_busy: the server's
// busy time per served frame (none where it served none).
DesignMetrics measuredMetrics(const runtime::DesignSummary& summary,
                              std::optional<double> server_busy_ms_mean);

// The calibrated runtime model's prediction: the metrics and what the model says besides.
struct RuntimePrediction {
    DesignMetrics metrics;
    double t_remote_ms_mean = 0.0;
    int frames_reused = 0;
};

// Signed error of a prediction, percent of the measurement, per compared metric (none where the
// measurement is 0 or either side has no value), and e1's in degrees.
struct PredictionError {
    std::array<std::optional<double>, kComparedMetrics.size()> pct{};
    double e1_deg_abs = 0.0;
    std::optional<double> pctOf(Metric metric) const;
};
PredictionError predictionError(const DesignMetrics& predicted, const DesignMetrics& measured);

// The machine's speed around a design (the mean of its probes before and after) over the
// calibration's speed reference, per side; none without probes or a reference.
std::optional<SideFactors> speedFactors(const DesignRun& run, const RuntimeCosts& calibrated);

// The runtime designs on the simulator's: fixed:E is FFR at E degrees. False for a name the
// simulator has no design for.
bool simDesignOf(const std::string& name, Design& design, double& fixed_e1_deg);

// The triangles one layer draws, the fragments one eye's fovea pass shades and those the
// server's render of one stream's layer shades (RuntimeSimConfig::layer_triangles,
// fovea_fragments, server_fragments).
using LayerTrianglesFn =
    std::function<double(int64_t frame, const LayerPlan& plan, int eye, int kind)>;
using FoveaFragmentsFn = std::function<double(int64_t frame, const LayerPlan& plan, int eye)>;
using ServerFragmentsFn = std::function<double(int64_t frame, int stream, double pixels)>;

// The server's fragments for a design as its own run's server counted them, per layer pixel
// (runtime::ServerBusy::fragments_per_px), times the model's layer pixels: a frame the server
// did not render for the design takes the nearest counted frame's; none counted: empty.
ServerFragmentsFn serverFragmentsOf(const std::vector<std::array<double, 4>>& fragments_per_px);

// The triangles each layer draws as the renderer draws them (level of detail `lod_px`, the
// periphery's holes unless `holes` is false) at frame k's head pose, counted off the clock: what
// qvr run's prediction and `qvr capacity --scene` charge the fovea and the server.
LayerTrianglesFn drawnLayerTriangles(std::shared_ptr<const DrawList> draw_list,
                                     const HmdProfile& profile, float lod_px, bool holes,
                                     std::function<Pose(int64_t frame)> head_pose_at);

// The run's knobs the models replay.
struct ModelSettings {
    std::string net;  // the run's --net spec
    uint64_t seed = 1;
    int pipeline_depth = 2;
    double remote_timeout_ms = 250.0;
    int warmup_frames = 0;
    bool record_scanout = false;
    // The headset's CFS share of its core (--headset-share): the model throttles its headset as
    // the quota does (RuntimeSimConfig::headset_share).
    double headset_share = 1.0;
    // Headsets on the one server (qvr run --headsets), all on the headset's core: the model runs
    // one of them with the capacity model's factors (sim/capacity.h capacityFactors).
    int headsets = 1;
};
ModelSettings modelSettings(const RunOptions& plan);

// One design's predictions on a workload whose frame k is the run's frame k.
struct DesignPrediction {
    std::optional<RuntimePrediction> calibrated;
    std::optional<SideFactors> speed;             // set where the probes give one
    std::optional<DesignMetrics> at_probe_speed;  // the calibrated model at `speed`
    std::optional<DesignMetrics> paper_hardware;  // the paper's model
};

// What a design's model run needs beyond the workload and the costs.
struct DesignModelInputs {
    std::string design;  // the run's label ("qvr", "fixed:10")
    std::optional<SideFactors> speed;
    LayerTrianglesFn layer_triangles;    // empty: the trace's BVH rings
    FoveaFragmentsFn fovea_fragments;    // empty: none known
    ServerFragmentsFn server_fragments;  // empty: none known
};

// Predicts one design: the calibrated model (and at the probes' speed when `speed` is set) on
// the link `settings.net` makes for it, and the paper's model on `paper_net` (none: no
// paper-hardware prediction). `frames`, when given, receives the calibrated model's frames.
// Nothing where simDesignOf knows no design of that name.
DesignPrediction predictDesign(const WorkloadTrace& trace, const DesignModelInputs& inputs,
                               const RuntimeCosts& calibrated, const ModelSettings& settings,
                               const std::optional<NetworkSpec>& paper_net,
                               std::vector<RuntimeFrame>* frames = nullptr);

// Every design of a run predicted, by design label.
struct RunPrediction {
    std::map<std::string, DesignPrediction> by_design;
    std::string workload_source;  // where the replayed workload came from
    size_t bits_frames_own = 0;   // frames charged the calibration's own bits for them
    std::string sim_note;         // why a prediction is missing or differs (empty: none)
};

// The workload the predictions replay, computed after the run off the clock (every frame's
// rings for the run's poses and gazes), the layers' triangles and the fovea's fragments, and
// every design's predictions; the calibrated model's frames go to out/predicted_frames.csv.
RunPrediction predictRun(const RunOptions& plan, const HmdProfile& profile,
                         const runtime::HeadsetInputs& inputs, const RuntimeCosts& calibrated,
                         const RunMeasurement& measurement);

}  // namespace qvr::experiment
