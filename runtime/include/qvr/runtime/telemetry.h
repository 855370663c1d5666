// Per-frame telemetry of the headset, every stage on one clock (issue 6, paper Fig. 4): pose
// sample, decision, local render, request, each stream received and decoded, UCA, scan-out.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/silence.h"

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
    // decoder, in RGBA): what the model charges as decode (docs/MODEL.md §8).
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
    // which the calibrated model charges the fovea by (docs/MODEL.md §8, "Fragments").
    double fovea_fragments = 0.0;
};

struct DesignSummary {
    std::string design;
    int frames = 0;
    int frames_displayed = 0;
    int frames_reused = 0;
    double fps_mean = 0.0;  // displayed frames per second of scan-out time
    double mtp_ms_mean = 0.0;
    double mtp_ms_p99 = 0.0;
    double bytes_per_frame_mean = 0.0;
    double e1_deg_mean = 0.0;
    double t_local_ms_mean = 0.0;
    // The headset's busy time per frame (FrameTelemetry::headset_busy_ms) over the counted frames
    // that have one (the first frame of a session has none); headset_busy_frames 0: no mean.
    double headset_busy_ms_mean = 0.0;
    int headset_busy_frames = 0;
    double t_remote_ms_mean = 0.0;  // over frames that requested remote layers
    double uca_ms_mean = 0.0;
    double frames_fallback_local = 0;
    double wall_s = 0.0;
    // The session's first frames (connection, the server's first render and key frame, first
    // use of every code path) are its start-up, not its steady state: they are left out of
    // every statistic above (with 150 frames the MTP p99 is the second-worst frame, which was
    // always frame 0 or 1 for every design) and their worst MTP is reported on its own. For a
    // design that asks the server for layers, the start-up lasts at least until the first of
    // them is on screen (FrameTelemetry::shown_frame ≥ 0), at most kMaxStartupFrames: a server
    // whose first frame takes longer than the wait limit leaves the headset re-warping nothing at
    // the refresh rate, and those frames are not the design's steady state. warmup_frames is the
    // number of frames the start-up took.
    int warmup_frames = 0;
    double startup_mtp_ms_max = 0.0;
    // No frame came past the start-up: the design asked for the server's layers and none of them
    // reached the screen (or the run was not longer than the warm-up). The statistics are then
    // over every frame, and a reader must not take them for the design's steady state.
    bool startup_unfinished = false;
};

// Statistics over frames[warmup_frames…] (all frames when there are no more than that).
DesignSummary summarizeRun(const std::string& design, const std::vector<FrameTelemetry>& frames,
                           int warmup_frames = 0);

// The same statistics, one frame at a time in display order, in memory that does not grow with
// the session (a `qvr client` may run for hours): the MTP p99 is exact over the first
// kExactMtpFrames frames and beyond that read from a log-spaced histogram (relative error
// ≤ 0.05%). summarizeRun is this over a vector.
class RunSummarizer {
public:
    static constexpr size_t kExactMtpFrames = size_t{1} << 16;
    static constexpr size_t kMaxStartupFrames = qvr::kMaxStartupFrames;  // the start-up's cap

    RunSummarizer(std::string design, int warmup_frames);
    void add(const FrameTelemetry& t);
    DesignSummary finish() const;

private:
    void count(const FrameTelemetry& t);
    double mtpP99() const;

    DesignSummary m_s;
    size_t m_warmup = 0;
    // The first warmup frames wait here until a later one proves they were the start-up (a
    // session of no more frames than that is summarized whole).
    std::vector<FrameTelemetry> m_startup;
    bool m_startup_done = false;
    double m_mtp_sum = 0.0, m_bytes = 0.0, m_e1 = 0.0, m_t_local = 0.0, m_t_remote = 0.0;
    double m_busy = 0.0;
    double m_uca = 0.0;
    int m_remote_frames = 0;
    int64_t m_first_display = -1, m_last_display = -1;
    int64_t m_first_pose_ns = 0, m_last_display_ns = 0;
    std::vector<double> m_mtp_exact;   // while no more than kExactMtpFrames
    std::vector<uint32_t> m_mtp_hist;  // after that (fixed size)
    double m_mtp_min = 0.0, m_mtp_max = 0.0;
};
// Nearest-rank percentile (p in (0, 100]) of a non-empty sample; 0 when empty.
double percentile(std::vector<double> values, double p);
std::string telemetryCsvHeader();
std::string telemetryCsvRow(const std::string& design, const FrameTelemetry& t);
Status writeTelemetryCsv(const std::string& path, const std::string& design,
                         const std::vector<FrameTelemetry>& frames);

}  // namespace qvr::runtime
