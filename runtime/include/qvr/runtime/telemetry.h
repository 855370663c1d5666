// Per-frame telemetry of the headset, every stage on one clock (paper Fig. 4): pose
// sample, decision, local render, request, each stream received and decoded, UCA, scan-out.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/run_summary.h"

namespace qvr::runtime {

inline constexpr int kStreams = 4;  // eye × {middle, outer}, net's stream ids

// Times are ns on the client's steady clock, relative to the run's start; -1 = did not happen.
struct FrameTelemetry {
    int64_t frame = 0;
    double e1_deg = 0.0;
    double e2_deg = 0.0;
    int64_t pose_ns = -1;
    int64_t decision_ns = -1;
    int64_t local_start_ns = -1;
    int64_t local_end_ns = -1;
    int64_t request_ns = -1;
    std::array<int64_t, kStreams> stream_rx_ns{-1, -1, -1, -1};       // last packet arrived
    std::array<int64_t, kStreams> stream_decoded_ns{-1, -1, -1, -1};  // decode finished
    int64_t remote_done_ns = -1;  // every stream this frame expected decoded
    int64_t uca_start_ns = -1;
    int64_t uca_end_ns = -1;
    int64_t display_ns = -1;  // the vsync slot it was scanned out at
    int64_t bytes = 0;        // media payload received for this frame's streams
    bool remote_requested = false;
    bool request_withheld = false;  // not asked: the request window was full (request_window.h)
    double server_ms = 0.0;    // the server's time on it, as its streams' headers said (0: unsaid)
    bool reused = false;       // the display re-warped older layers (remote layers late/lost)
    int64_t shown_frame = -1;  // the frame whose layers were displayed
    bool connected = false;
    bool fallback_local = false;  // the server was gone: everything rendered locally
    double t_local_ms = 0.0;
    // From when the server could start on the frame to the last packet of its last stream: the
    // server's render + encode + the link. Decoding is the headset's work (in its busy time), and
    // waits while the headset renders its fovea, so it is not part of T_remote.
    double t_remote_ms = 0.0;
    double t_remote_decoded_ms = 0.0;  // the same, to the last stream decoded
    double t_local_pred_ms = 0.0;      // the policy's prediction (0 when it made none)
    double t_remote_pred_ms = 0.0;
    double probe_ms = 0.0;  // the pre-render triangle-ring count (LIWC's input)
    // The headset's decodes of this frame's streams, the calls alone (the picture out of the
    // decoder, in RGBA): what the model charges as decode (docs/MODEL.md §9).
    double decode_ms = 0.0;
    double uca_ms = 0.0;
    // The headset's busy time for this frame (its decision, fovea, decodes, UCA, bookkeeping:
    // everything but waiting for the network and for vsync). With frames in flight this, not the
    // fovea render alone, is what LIWC balances against T_remote (docs/RUNTIME.md).
    double headset_busy_ms = 0.0;
    double mtp_ms = 0.0;  // pose sample → UCA output complete
    double throughput_bps = 0.0;
    double fovea_triangles = 0.0;  // both eyes, in the e1 cone (LIWC's input)
    double warp_deg = 0.0;
    // The fragments its fovea (or whole-frame) passes shaded, both eyes (RenderStats::
    // fragment_invocations; 0 where the driver does not count them): the workload's overdraw,
    // which the calibrated model charges the fovea by (docs/MODEL.md §9).
    double fovea_fragments = 0.0;
};

// One design's run: its label and the statistics every pipeline reports (qvr/core/run_summary.h).
struct DesignSummary : RunStats {
    std::string design;
};

// The run summary of a design's frames, one frame at a time in display order, in memory that
// does not grow with the session (FrameSummarizer); summarizeRun is this over a vector.
class RunSummarizer {
public:
    RunSummarizer(std::string design, int warmup_frames);
    void add(const FrameTelemetry& t);
    DesignSummary finish() const;

private:
    std::string m_design;
    FrameSummarizer m_frames;
};

// What the summary reads of a frame's telemetry.
FrameSample frameSample(const FrameTelemetry& t);
// Statistics over frames[warmup_frames…] (all frames when there are no more than that).
DesignSummary summarizeRun(const std::string& design, const std::vector<FrameTelemetry>& frames,
                           int warmup_frames = 0);

std::string telemetryCsvHeader();
std::string telemetryCsvRow(const std::string& design, const FrameTelemetry& t);
Status writeTelemetryCsv(const std::string& path, const std::string& design,
                         const std::vector<FrameTelemetry>& frames);

}  // namespace qvr::runtime
