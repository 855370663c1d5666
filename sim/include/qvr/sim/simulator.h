// The trace-driven pipeline simulator (paper §2.3 Fig. 4, §5): each frame of a workload trace
// becomes timed tasks on the headset's units (CPU, mobile GPU, LIWC, UCA, video decoder,
// display), the link and the server, with the overlaps of Fig. 4; the design decides what runs
// where and which policy sizes the fovea. Metrics follow §6's definitions.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "qvr/controller/policy.h"
#include "qvr/core/design.h"
#include "qvr/core/run_summary.h"
#include "qvr/sim/energy.h"
#include "qvr/sim/hardware.h"
#include "qvr/sim/network.h"
#include "qvr/workload/workload.h"

namespace qvr {

struct SimConfig {
    std::string bench;  // a label for the records
    Design design = Design::Qvr;
    HardwareConfig hardware = defaultHardware(500.0);
    int frames = 300;  // clamped to the trace's length
    // How the headset measures T_local for the policy and the metrics: from the GPU's first
    // cycle on the frame (timestamp queries, what the paper's GPU timers see: preemptions count,
    // waiting behind a composition/ATW pass does not; the default) or from submission (waits
    // count). docs/MODEL.md §6 shows what it changes.
    bool t_local_from_submission = false;
    // Frames start at most once per refresh period and each is shown at the first vsync after
    // its display path ends (MTP runs to that vsync); off: shown when ready.
    bool vsync_paced = false;
    // The oracle policy (knows each frame's true cost curve) picks e1 instead of the design's
    // own: the floor a foveated design's balance is checked against (Fig. 14).
    bool oracle_policy = false;
};

// One simulated frame. What every pipeline's summary reads of a frame is core's FrameSample
// (qvr/core/run_summary.h), in ms from the first frame's control logic: pose_ms is when the
// control logic begins (the pose has arrived), display_ms when the frame is on the display
// (display_ready_ms, or its vsync when paced), mtp_ms = 2 ms sensor + pipeline + 5 ms display,
// t_local_ms submission → render end (waits and preemptions included), t_remote_ms request →
// remote layers decoded where remote_requested, bytes the downlink payload, uca_ms the UCA's wall
// time (both units), e1_deg 0 for designs without a fovea. The rest is the simulator's own.
struct FrameRecord : FrameSample {
    int64_t index = 0;
    double e2_deg = 0.0;
    // Event times, ms from the first frame's control logic.
    double request_ms = 0.0;
    double render_start_ms = 0.0;
    double render_end_ms = 0.0;
    double remote_ready_ms = 0.0;
    double display_ready_ms = 0.0;  // composition + ATW done
    // Durations.
    double render_work_ms = 0.0;  // local render at the GPU's rate, no interruptions
    double net_ms = 0.0;          // transmission alone
    double server_render_ms = 0.0;
    double encode_ms = 0.0;
    double decode_ms = 0.0;
    double comp_ms = 0.0;             // on the GPU
    double atw_ms = 0.0;              // on the GPU
    double gpu_ms = 0.0;              // T_GPU: GPU busy time this frame
    double display_dram_bytes = 0.0;  // composition + ATW (GPU passes or UCA): read + written
    double display_dram_ms = 0.0;     // those bytes at Table 2's DRAM bandwidth
    double radio_w = 0.0;             // radio power while this frame's payload arrives
    int preemptions = 0;
    double goodput_bps = 0.0;
    double shaded_pixels = 0.0;  // both eyes, every layer at its own resolution
    double fps = 0.0;            // min(1/T_GPU, 1/T_network)
    double latency_ratio = 0.0;  // T_remote / T_local, 0 when either is absent
    FrameEnergy energy;
};

// One run's statistics over all its frames. Those every pipeline shares are core's run
// summariser's (qvr/core/run_summary.h FrameSummarizer, no start-up left out; percentiles nearest
// rank): mtp_ms_mean, mtp_ms_p99, fps_pipeline (its fps_mean), bytes_per_frame_mean, e1_deg_mean
// (and e1_deg_steady, with the warm-up left out), t_local_ms_mean, t_remote_ms_mean (over the
// frames that fetched remote layers) and uca_ms_mean. The rest only the simulator knows.
struct RunSummary {
    std::string bench;
    std::string design;
    double gpu_mhz = 0.0;
    std::string net;
    int frames = 0;
    double mtp_ms_mean = 0.0;
    double mtp_ms_p99 = 0.0;
    double fps_mean = 0.0;      // 1000 / mean(max(T_GPU, T_network))
    double fps_pipeline = 0.0;  // frames displayed per second in the event timeline
    double bytes_per_frame_mean = 0.0;
    double pixels_per_frame_mean = 0.0;
    double energy_mj_per_frame = 0.0;
    FrameEnergy energy_mean;
    double e1_deg_mean = 0.0;
    double e1_deg_steady = 0.0;        // mean over frames after steadyStateStart
    double latency_ratio_final = 0.0;  // median (nearest rank) over the last 30 frames
    double t_local_ms_mean = 0.0;
    double t_remote_ms_mean = 0.0;
    double render_wait_ms_mean = 0.0;  // T_local − render work: time behind/preempted by passes
    double gpu_ms_mean = 0.0;
    double net_ms_mean = 0.0;
    double preemptions_per_frame = 0.0;
    double comp_ms_mean = 0.0;
    double atw_ms_mean = 0.0;
    double uca_ms_mean = 0.0;
    double display_dram_mb_per_frame = 0.0;
    double display_dram_ms_mean = 0.0;
    double radio_w_max = 0.0;    // the most the radio drew while receiving, any frame
    bool meets_refresh = false;  // fps_mean ≥ the HMD's refresh rate
};

struct RunResult {
    std::vector<FrameRecord> frames;
    RunSummary summary;
};

// The first frame from which a run counts as steady (Table 4 averages after it).
int steadyStateStart(int frames);

// The policy a design uses, built by name; nullptr for designs without a fovea.
Expected<std::unique_ptr<FoveaPolicy>> makeDesignPolicy(Design design, const WorkloadHeader& header,
                                                        double link_nominal_bps);

// Runs one design over a trace on a link. The trace must outlive the call.
RunResult simulate(const WorkloadTrace& trace, const SimConfig& config, Link& link);

RunSummary summarize(const std::vector<FrameRecord>& frames, const SimConfig& config,
                     const std::string& net_name, double refresh_hz);

}  // namespace qvr
