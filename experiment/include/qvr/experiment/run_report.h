// What `qvr run` found, as one typed result — per design what its run measured, what the models
// predicted, their errors, its image quality and its transport counters; the run's setting,
// calibration, machine speed, server, timeline and video — and everything written from it:
// summary.json and report.html with its figures.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/experiment/design_runs.h"
#include "qvr/experiment/prediction.h"
#include "qvr/experiment/run_plan.h"

namespace qvr::experiment {

// What limits a design's frame rate on this machine: the headset's busy time per frame (its
// core) against the server's service time per frame (T_remote), and the headset's stages.
struct DesignLimits {
    double headset_busy_ms = 0.0;  // over the frames that have one
    double decision_ms = 0.0, local_ms = 0.0, uca_ms = 0.0;
    double t_remote_ms = 0.0;  // over the frames that asked for remote layers
    std::string limit;         // which side, and the headset's largest stage
};
// None without frames.
std::optional<DesignLimits> designLimits(const std::vector<runtime::FrameTelemetry>& frames);

// One design's run: what it measured, what was predicted, the errors, its quality, its counters.
struct DesignResult {
    DesignSpec spec;
    std::string name;  // the label: "qvr", "fixed:10"
    runtime::DesignSummary summary;
    runtime::HeadsetStats stats;  // the headset's transport and security counters
    DesignMetrics measured;
    std::optional<SpeedSample> speed_before, speed_after;
    DesignPrediction prediction;           // empty where the design was not predicted
    std::optional<PredictionError> error;  // of prediction.calibrated
    std::optional<PredictionError> error_at_probe_speed;  // of prediction.at_probe_speed
    std::optional<DesignLimits> limits;
    std::optional<DesignQuality> quality;
};
DesignResult designResult(const DesignRun& run, std::optional<runtime::ServerBusy> server_busy,
                          const DesignPrediction* prediction, const DesignQuality* quality);

struct RunOutcome {
    std::string command, date, machine;
    std::string scene;  // its name
    HmdProfile profile;
    std::string net;
    int frames_per_design = 0, warmup_frames = 0, pipeline_depth = 2, quality_every = 0;
    bool fovea_border = true;
    bool interrupted = false;
    std::string interrupted_note;
    size_t designs_requested = 0;
    int client_core = 0, server_core = -1, cores = 1;
    double run_seconds = 0.0;  // from the start to the end of the runs
    double headset_share = 1.0;
    std::optional<runtime::CpuShareGroup::Throttling> headset_throttling;
    std::string cgroup;
    std::vector<DesignResult> designs;  // in the order they ran
    CalibrationChoice calibration;
    std::string workload_source;
    size_t bits_frames_own = 0;
    std::string speed_note;
    RunSpeed speed;
    std::string sim_note;
    nlohmann::json server_stats = nlohmann::json::object();
    int server_status = 0;
    std::optional<runtime::ChromeTraceInfo> trace;
    std::string trace_note;
    std::string quality_note;
    DisplayVideo video;
    std::vector<std::string> never_shown;
    std::vector<std::string> stale_only;
    // Every design's headsets (one each unless qvr run --headsets N), in the order they ran.
    int headsets = 1;
    bool identical_workloads = false;
    double headset_offset_ms = 0.0;
    std::vector<HeadsetsResult> headsets_by_design;
};

// The run's outcome from its plan, measurement and predictions.
RunOutcome runOutcome(const RunOptions& plan, const HmdProfile& profile,
                      const std::string& scene_name, size_t designs_requested,
                      const CalibrationChoice& calibration, const RunMeasurement& measurement,
                      const RunPrediction& prediction, DisplayVideo video, double run_seconds);

// The fixed design run (ffr is fixed:5) with the most frames a second shown with their own layers
// (core/run_summary.h ownLayersFps, beatsForBestFixed), in hindsight, and the adaptive designs'
// (qvr, sw) such FPS over it (infinite over a fixed design that showed none of its own).
struct BestFixed {
    std::string design;
    double e1_deg = 0.0, fps_mean = 0.0, mtp_ms_p99 = 0.0;
    std::vector<std::pair<std::string, double>> fps_over_best;  // adaptive design → ratio
};
std::optional<BestFixed> bestFixed(const std::vector<DesignResult>& designs);
// summary.json's "best_fixed".
nlohmann::json bestFixedJson(const BestFixed& best);

// The headline ratios: measured here, the paper's, the paper-hardware model's.
struct HeadlineRatios {
    static constexpr double kPaperQvrFpsOverLocal = 3.4;
    static constexpr double kPaperQvrBytesSavedVsRemote = 0.85;
    std::optional<double> qvr_fps_over_local, qvr_bytes_saved_vs_remote;
    std::optional<double> sim_qvr_fps_over_local, sim_qvr_bytes_saved_vs_remote;
};
HeadlineRatios headlineRatios(const std::vector<DesignResult>& designs);

// summary.json's content.
nlohmann::json summaryJson(const RunOutcome& outcome);
// One design's entry of summary.json's "designs".
nlohmann::json designJson(const DesignResult& design);
nlohmann::json ratiosJson(const HeadlineRatios& ratios);

// The report's table of the measurements against the simulators, per design.
std::string validationHtml(const RunOutcome& outcome);

// Writes summary.json, the figures (gnuplot, with their CSVs) and report.html into `out`.
void writeRunReport(const RunOutcome& outcome, const std::filesystem::path& out);

}  // namespace qvr::experiment
