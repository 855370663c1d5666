// Running a plan's designs for real: a render server (`qvr server` in a child process, pinned to
// the last core) and a headset client (this process, pinned to core 0) on loopback, every design
// in turn over the same frames through net's link emulator (paper Fig. 4, §6.1), with the
// machine's speed probed around each design, image quality sampled after each, and what every
// run measured: per-frame telemetry, the server's counters and stamps, the display video.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/codec/mp4_writer.h"
#include "qvr/core/design.h"
#include "qvr/experiment/calibration.h"
#include "qvr/experiment/headsets.h"
#include "qvr/experiment/run_plan.h"
#include "qvr/experiment/scanout_recorder.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/chrome_trace.h"
#include "qvr/runtime/cpu_share.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/session.h"

namespace qvr::experiment {

// The display of a design against the full-resolution render of the same frame, by band,
// averaged over the sampled frames (PSNR averaged in dB, capped at 99 dB for identical images).
struct DesignQuality {
    static constexpr std::array<const char*, 5> kBands = {"fovea", "blend", "middle", "outer",
                                                          "all"};
    int frames = 0;
    std::array<double, 5> psnr_db{};  // by kBands
    std::array<double, 5> ssim{};
    std::array<int, 5> counted{};
    std::map<double, std::pair<double, int>> psnr_by_ecc;  // bin centre → (sum, n)
    double seconds = 0.0;
};

// One displayed frame kept for the quality pass: the left eye at full resolution and what its
// reference needs: the plan it showed, the frame whose layers it showed, and when UCA ran.
struct QualitySample {
    int64_t frame = 0;
    int64_t shown_frame = 0;
    int64_t pose_ns = 0;
    int64_t uca_start_ns = 0;
    LayerPlan plan;
    ImageRgba8 left;
};

// The sampled displays against full-resolution renders of the same frames: the shown frame's
// content pose for the render, the newest pose when UCA ran for the display.
Expected<DesignQuality> measureDesignQuality(const std::vector<QualitySample>& samples,
                                             const HmdProfile& profile,
                                             const runtime::HeadsetTraces& traces,
                                             Renderer& renderer);

struct DesignRun {
    DesignSpec spec;
    runtime::HeadsetResult result;
    // The machine's speed just before and just after the design ran (calibration.h SpeedProbe).
    std::optional<SpeedSample> speed_before, speed_after;
    Design design() const { return spec.design; }
    std::string label() const { return spec.label(); }
};

// How far the machine's speed moved over the run: every probe's spread per side, and their mean
// over the calibration's reference. A host that moves within a design (seconds) moves its FPS by
// as much, which no probe between designs can follow; the run says so rather than let the error
// look like the model's.
struct RunSpeed {
    std::array<double, 2> spread_pct{0.0, 0.0};      // headset, server: max / min − 1
    std::array<double, 2> over_reference{0.0, 0.0};  // headset, server (0: no probes)
    bool unsteady = false;                           // a spread over kUnsteadySpeedPct
};
RunSpeed runSpeed(const std::vector<DesignRun>& runs, const RuntimeCosts& calibrated);

// Everything the designs' runs measured.
struct RunMeasurement {
    std::vector<DesignRun> runs;
    std::vector<std::pair<std::string, DesignQuality>> quality;  // by design label, run order
    std::string quality_note;  // why a design has no quality (empty: none missing)
    bool interrupted = false;  // SIGINT or SIGTERM: the designs not run are left out
    std::string interrupted_note;
    // Designs that asked for the server's layers and never showed one: their display was stale
    // throughout.
    std::vector<std::string> never_shown;
    // Designs that showed the server's layers in their start-up and none newer in every counted
    // frame after: the same old periphery re-warped at full rate (showedNoNewLayers).
    std::vector<std::string> stale_only;
    std::string speed_note;  // why there are no speed probes (empty: there are)
    RunSpeed speed;
    int client_core = 0, server_core = -1, cores = 1;
    std::optional<runtime::CpuShareGroup> share_group;       // --headset-share under 1
    nlohmann::json server_stats = nlohmann::json::object();  // as the server wrote them on exit
    int server_status = 0;
    std::optional<runtime::ChromeTraceInfo> trace;  // trace.json, when written
    std::string trace_note;
    std::vector<runtime::ServerBusy> server_busy;  // per design, in the order of runs
    bool recorded_workload = false;                // workload.jsonl by the qvr design
    std::unique_ptr<ScanoutRecorder> recorder;     // what the qvr design's headset displayed
    // Every headset of each design (headset 0 is the one `runs` holds), in the order of runs.
    std::vector<HeadsetsResult> headsets;
};

// Why the designs could not be run: the message (after "qvr run: ") and the exit status.
struct RunError {
    std::string message;
    int exit_status = 1;
};

// Runs every design of `designs` in turn (with plan.headsets headsets at once), writing
// telemetry.csv, frames_<design>.csv, workload.jsonl, server_*.csv, server_stats.json and
// trace.json into plan.out as it goes. SIGINT or SIGTERM ends the current design at its next frame
// boundary and starts no other.
std::variant<RunMeasurement, RunError> measureDesigns(const RunOptions& plan,
                                                      const std::vector<DesignSpec>& designs,
                                                      const HmdProfile& profile,
                                                      const runtime::HeadsetInputs& inputs,
                                                      const RuntimeCosts& calibrated);

// The qvr design's display as qvr_display.mp4 and a still, and the MP4 read back through
// libavformat as a player sees it.
struct DisplayVideo {
    std::string note = "not recorded";
    std::optional<VideoFileInfo> info;
};
DisplayVideo writeDisplayVideo(const RunOptions& plan, const HmdProfile& profile,
                               const RunMeasurement& measurement);

// The warning a design's console line gets when most of its counted frames re-warped an older
// periphery (their own layers came after the wait limit): its FPS then counts frames whose
// periphery is stale. None when half or fewer did.
std::optional<std::string> reusedPeripheryWarning(const runtime::DesignSummary& s);
// A design that asked for the server's layers in its counted frames, came past its start-up, and
// put none newer on screen: its FPS is a re-warp of the start-up's periphery.
bool showedNoNewLayers(const runtime::DesignSummary& s);

}  // namespace qvr::experiment
