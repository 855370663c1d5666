// LIWC, the Lightweight Interaction-Aware Workload Controller (paper §4.1, Eq. 2). Each frame:
// encode the motion, predict T_local and T_remote for the delta tags −5…+5° around the current
// e1 from the frame's triangles in the fovea cone and the periphery's predicted bytes, add the
// table's learned offset for (motion, eccentricity), and take the tag that best cancels the
// imbalance. After the frame, fold the measured error into the table and refresh the GPU-rate
// and throughput estimates. Choices where §4.1 is vague: docs/LIWC.md.
#pragma once

#include <algorithm>
#include <array>
#include <deque>
#include <optional>
#include <string_view>
#include <vector>

#include "qvr/controller/liwc_table.h"
#include "qvr/controller/motion_codec.h"
#include "qvr/controller/policy.h"
#include "qvr/controller/remote_size_table.h"
#include "qvr/controller/windowed_fit.h"

namespace qvr {

struct LiwcConfig {
    double e1_initial_deg = 5.0;
    double e1_min_deg = 1.0;
    double e1_max_deg = 90.0;
    int max_delta_deg = 5;    // delta tags −5…+5
    bool interpolate = true;  // refine between the two tags that bracket the balance point
    float alpha = 0.3f;       // the table's reward parameter α
    double rate_ema = 0.5;  // weight of a new measurement in the GPU-rate/throughput/bits estimates
    int table_warmup_frames = 3;  // frames that train only the estimates, not the table
    MotionThresholds motion;
    // The GPU-rate estimate forgets old frames with this factor (recursive least squares).
    double gpu_forgetting = 0.95;
    // Cold-start estimates, before anything is measured.
    double gpu_triangles_per_ms_initial = 50'000.0;
    double gpu_pixels_per_ms_initial = 150'000.0;
    double throughput_bps_initial = 200e6;
    double bits_per_pixel_initial = 1.0;
    double bits_scale_exponent_initial = 0.7;
    // Eq. 2 charges the remote side only the transmission of the periphery, as if the server
    // rendered and encoded in no time (the paper's server is far stronger than the headset).
    // When set, LIWC also learns the rest of the measured T_remote — the server's render and
    // encode time, the decode — as a running mean, and adds it to every candidate (docs/LIWC.md).
    // The runtime sets it; the simulator keeps the paper's Eq. 2.
    bool learn_remote_base = false;
    // The runtime's objective (docs/LIWC.md "The runtime's objective"): the pipelined frame
    // period. With frames in flight the headset, the server and the link work on different frames
    // at once, so the display's period is the slowest stage's — the headset's busy time L(e1),
    // the server's render + encode S(e1), the link's time X(e1) = bytes / measured throughput —
    // and no shorter than the remote chain over the frames in flight:
    // P(e1) = max(L, S, X, (S + X) / frames_in_flight). LIWC picks the candidate minimising
    // P, ties (within period_tie) going to the lower L + S + X (motion-to-photon); a move away
    // from the current e1 also pays the bytes a change costs the encoders (a new canvas, a key
    // frame, padding), as measured, spread over the frames a chosen e1 is measured to hold. S(e1)
    // is learned as a linear function of the periphery's triangles and pixels. False keeps
    // Eq. 2's balance |T_remote − T_local| → 0, which the simulator reproduces.
    bool frame_period_objective = false;
    int frames_in_flight = 2;  // the runtime's pipeline depth
    double period_tie = 0.03;  // candidates within 3% of the best period count as equal
    // The software-reactive variant of the paper (§6.1, "SW"): the same model, but with no
    // pre-render triangle counts (each decision reads the rings of the newest observed frame)
    // and no direct view of the acknowledgements (the throughput it uses is that of the newest
    // observed frame).
    bool reactive = false;
};

struct LiwcCandidate {
    int delta_deg = 0;
    double e1_deg = 0.0;
    double t_local_pred_ms = 0.0;
    double t_remote_pred_ms = 0.0;
    double offset_ms = 0.0;
    double imbalanceMs() const { return t_remote_pred_ms - t_local_pred_ms + offset_ms; }
};

class LiwcPolicy final : public FoveaPolicy {
public:
    LiwcPolicy(const WorkloadHeader& header, LiwcConfig config = {});

    std::string_view name() const override { return "liwc"; }
    Decision decide(const WorkloadFrame& frame) override;
    void observe(const FrameMeasurement& m) override;
    // A late periphery's sizes teach the bits law as a frame on time does: on a link slower
    // than the wait limit they are the only sizes there are (docs/LIWC.md, T̂_remote).
    void observeLateArrival(const LateArrival& a) override;

    // The link's throughput as the acknowledgements show it now (the hardware monitors them at
    // decision time, §4.1); ignored by the reactive variant.
    void setLinkEstimate(double throughput_bps);
    // The fraction of a core the headset's CPU quota allows (runtime/cpu_share.h
    // cpuQuotaShare; 1: none). Under a quota s a ms more of the fovea's render costs the
    // headset 1/s ms of wall time once the quota throttles it, while the render's own time,
    // measured before the throttle lands, rises by that ms alone: L's slope in e1 is the render's
    // over s, and so is the periphery's decode, which falls as e1 grows (docs/LIWC.md "Fits").
    // Values outside (0, 1] read as 1.
    void setHeadsetShare(double share);
    double headsetShare() const { return m_headset_share; }

    // Eq. 2 with the current estimates, without the table's offset.
    double predictLocalMs(const WorkloadFrame& frame, double e1_deg) const;
    double predictRemoteMs(const WorkloadFrame& frame, double e1_deg) const;

    const LiwcTable& table() const { return m_table; }
    LiwcTable& table() { return m_table; }
    double gpuTrianglesPerMs() const;
    double gpuPixelsPerMs() const;
    double throughputBps() const { return m_throughput_bps; }
    double bitsPerPixelAt(double scale) const;
    const std::array<LiwcCandidate, 11>& lastCandidates() const { return m_candidates; }
    uint16_t lastMotion() const { return m_motion; }

private:
    void updateGpuRates(double triangles, double pixels, double t_local_ms);
    void remember(const Decision& d);
    static constexpr size_t kMaxPendingDecisions = 8;
    static constexpr double kFarStepDeg = 2.5;  // the coarse grid decidePeriod also scans
    // Per-frame quantities every candidate shares: computed once in decide().
    void prepareFrame(const WorkloadFrame& frame) const;
    double localMs(double e1_deg) const;
    // frame_period_objective, render apart: the fovea render's fit at e1 for its cone's counts.
    double renderMs(double tris, double pixels, double e1_deg) const;
    // The CPU a candidate's fovea and periphery cost the headset: its render and its decode.
    double headsetCpuMs(double e1_deg) const;
    // The periphery's decode at e1 (0 once the fovea covers the frame), fitted on held frames.
    double decodeMs(double e1_deg) const;
    double remoteMs(const Gaze& gaze, double e1_deg) const;
    // frame_period_objective: the server's part and the transmission, separately.
    double transmissionMs(const Gaze& gaze, double e1_deg) const;
    // The link's throughput the objective uses: the acks' estimate at decision time (the
    // reactive variant: its observed frames'), relaxing toward the prior over frames that sent
    // nothing, with time constant kStaleLinkFrames (about a second of frames) times the backoff
    // (doubled by each try of the link that came late again, up to kMaxStaleLinkBackoff).
    double linkBps() const;
    static constexpr double kStaleLinkFrames = 30.0;
    static constexpr double kMaxStaleLinkBackoff = 16.0;  // the longest wait: 16x
    // What a move adds to a frame's link time and server time, as fractions of them: the
    // measured extra of a moved frame over the next frame that held its e1, spread over the
    // frames a chosen e1 is measured to hold (docs/LIWC.md).
    struct MoveCost {
        double link = 0.0;
        double server = 0.0;
    };
    MoveCost moveCost() const;
    // What an observed frame was: the session's first (its encoders' opening key frames); e1
    // held; e1 moved; or e1 held but its encoders opened a new canvas (a move's late cost).
    // Every kind but kHeld is kept apart from the steady-state fits.
    enum class FrameKind { kOpening, kHeld, kMoved, kLateCanvas };
    FrameKind learnMoveCost(const FrameMeasurement& m, double predicted_bits);
    // What the server took of a frame, from its T_remote and its transmission (sent_ms).
    double serverMsOf(const FrameMeasurement& m, double sent_ms) const;
    // Both eyes' middle and outer layers' bits at e1 (0 once the fovea covers the frame).
    double peripheryBits(const Gaze& gaze, double e1_deg) const;
    double peripheryTriangles(double e1_deg) const;
    double peripheryPixels(const Gaze& gaze, double e1_deg) const;
    // The largest e1 a candidate may take: hi, or one window step past the largest measured.
    double trustedTop(double hi) const;
    Decision decidePeriod(const WorkloadFrame& frame, double lo, double hi);
    static double prefixAt(const std::vector<double>& prefix, double ring_deg, double e_deg);

    // A cache of the frame being decided, so mutable.
    mutable double m_cover_deg = 90.0;
    mutable Gaze m_gaze;
    mutable std::vector<double> m_prefix_tris;  // [k] = triangles in rings < k
    mutable std::vector<double> m_prefix_pixels;

    const WorkloadHeader& m_header;
    LiwcConfig m_config;
    LiwcTable m_table;
    // frame_period_objective: the cells a frame has folded, and the remote chain's error over
    // all of them (remoteOffsetMs, foldRemoteOffset).
    std::vector<bool> m_cell_folded = std::vector<bool>(LiwcTable::kEntries, false);
    double m_remote_residual_ms = 0.0;
    double remoteOffsetMs(uint16_t motion, int bucket) const;
    void foldRemoteOffset(uint16_t motion, int bucket, double delta_ms);
    RemoteSizeTable m_sizes;
    // Estimates the updater refreshes. The GPU: T_local ≈ θ0 + θ1·triangles + θ2·pixels (in
    // units of 1e5), fitted by recursive least squares with covariance m_gpu_cov.
    std::array<double, 3> m_gpu_theta;
    std::array<double, 9> m_gpu_cov;
    double m_throughput_bps;
    double m_log_bits_at_1;  // log of bits per pixel at scale 1
    double m_bits_exponent;  // growth with scale
    // frame_period_objective: each layer's bits over the law's, in log space (EMA over held
    // frames): the content the law cannot tell from scale.
    static constexpr int kMiddle = 0, kOuter = 1;
    std::array<double, 2> m_layer_log_ratio{0.0, 0.0};
    double layerBitsPerPixel(int layer, double scale) const;
    double m_remote_base_ms = 0.0;  // learn_remote_base: T_remote beyond the transmission
    // frame_period_objective, both fits over a window (windowed_fit.h), in units of 1e5: the fovea
    // render (or, not measured apart, the whole busy time) ≈ λ·[1, fovea triangles, fovea
    // pixels], and S ≈ σ·[1, periphery triangles, periphery pixels].
    WindowedFit m_local_fit;
    WindowedFit m_server_fit;
    // When frames say their fovea render apart (FrameMeasurement::t_render_ms), m_local_fit fits
    // the render alone and the rest of the headset's busy time (UCA, decode, the frame's
    // overheads, the host's preemptions) is its mean over the same window: L = rest + render.
    bool m_render_apart = false;
    double m_headset_share = 1.0;
    WindowedFit m_decode_fit{WindowedFit::Vec{0.0, 0.0, 0.0}};  // [1, middle, outer pixels]
    std::deque<double> m_local_rest;
    double m_local_rest_sum = 0.0;
    void learnLocal(const FrameMeasurement& m);
    double m_link_bps = 0.0;            // setLinkEstimate
    int m_frames_without_link = 0;      // observed frames in a row that carried no periphery
    double m_stale_link_backoff = 1.0;  // scales kStaleLinkFrames: doubled by a failed try
    // frame_period_objective: what moving e1 costs the bits (a new canvas is a key frame, a grown
    // one carries padding) and the server's time (the key frames' encode), measured per move.
    static constexpr double kMoveEmaWeight = 0.2;  // the move-cost EMAs' and frames-between's
    class MoveMeter {
    public:
        // A frame's value (its server time; its bits over the bits law's) and whether its e1
        // moved (or its encoders opened a new canvas).
        void add(bool was_moved, double e1_deg, double value);
        // EMA over moves of a moved frame's value over the next held frame's at its e1, − 1;
        // at least 0, and 0 until one is measured.
        double extra() const { return m_have ? std::max(0.0, m_extra) : 0.0; }

    private:
        struct Pending {
            double e1_deg = 0.0, value = 0.0;
        };
        std::optional<Pending> m_pending;  // the newest moved frame, until the next observed
        double m_extra = 0.0;
        bool m_have = false;
    };
    MoveMeter m_move_bits;
    MoveMeter m_move_server;
    // The bits law, b·s^γ per layer pixel, fitted in log space to a held frame's layers.
    void learnBits(double middle_bits, double middle_pixels, double s1, double outer_bits,
                   double outer_pixels, double s2);
    // Held frames observed late, whose periphery may still arrive (observeLateArrival).
    struct LateFrame {
        int64_t index = 0;
        double middle_pixels = 0.0, outer_pixels = 0.0, s1 = 1.0, s2 = 1.0;
    };
    static constexpr size_t kMaxLateFrames = 64;  // the runtime holds no more pending frames
    std::deque<LateFrame> m_late;
    bool m_server_says = false;        // frames carry the server's own time (server_ms)
    bool m_seen_held_frame = false;    // a frame whose e1 held has been observed
    bool m_bits_law_measured = false;  // the bits law has been measured
    // The period objective's bits law takes its first measurement outright (the prior is far off).
    bool replacesPrior() const { return m_config.frame_period_objective && !m_bits_law_measured; }
    double m_frames_between_moves = 1.0;
    int m_frames_since_move = 0;
    double m_last_observed_e1_deg = -1.0;
    double m_last_arrival_ms = 0.0;  // the newest observed frame's last periphery packet
    // reactive: the rings of the newest observed frame, and those of frames not yet observed.
    struct SeenFrame {
        int64_t index = 0;
        std::vector<double> triangles_per_ring;
        std::vector<double> pixels_per_ring;
    };
    std::deque<SeenFrame> m_seen;
    std::optional<SeenFrame> m_reactive_rings;
    // State between decide() and observe().
    bool m_have_previous = false;
    Pose m_previous_head;
    Gaze m_previous_gaze;
    double m_e1_deg;
    uint16_t m_motion = 0;
    std::array<LiwcCandidate, 11> m_candidates{};
    // Decisions not yet observed, oldest first. observe() comes in frame order, but a pipelined
    // headset decides frame n+1 before frame n completes, so more than one can be outstanding.
    struct PendingDecision {
        uint16_t motion = 0;
        int bucket = 0;
        double model_imbalance_ms = 0.0;
        double periphery_triangles = 0.0;  // both eyes, beyond e1 (frame_period_objective)
        double periphery_pixels = 0.0;     // both eyes, middle + outer layer pixels
    };
    std::deque<PendingDecision> m_pending;
    int m_observed = 0;
    bool m_first_decision = true;
};

}  // namespace qvr
