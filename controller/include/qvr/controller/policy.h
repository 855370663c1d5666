// Fovea-sizing policies behind one interface (paper §4.1, §6): each frame a policy picks e1
// before the frame renders, and later observes what the frame measured. Which measurements a
// policy may use, and when, is the difference between them: LIWC reads the frame's own
// triangles before rendering; the software-reactive policy sees measurements two frames late
// (Fig. 4); the oracle knows the frame's true latency curve.
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include "qvr/workload/cost_model.h"
#include "qvr/workload/workload.h"

namespace qvr {

struct Decision {
    double e1_deg = 5.0;
    // The policy's own prediction for this frame at the chosen e1 (NaN if it makes none).
    double t_local_pred_ms = 0.0;
    double t_remote_pred_ms = 0.0;
};

// What the headset measures about a frame once it is done.
struct FrameMeasurement {
    int64_t index = 0;
    double e1_deg = 0.0;
    double t_local_ms = 0.0;
    // When t_local_ms is the headset's whole busy time (frames in flight): the part of it that
    // rendered the fovea, the only part e1 moves (0: not measured apart).
    double t_render_ms = 0.0;
    // The headset's decode calls for the frame's periphery (0: not measured).
    double t_decode_ms = 0.0;
    double t_remote_ms = 0.0;
    double triangles_local = 0.0;  // triangles in the fovea cone, both eyes
    double pixels_local = 0.0;     // shaded fovea pixels, both eyes
    double middle_bytes = 0.0;
    double outer_bytes = 0.0;
    double middle_pixels = 0.0;  // both eyes, at s1
    double outer_pixels = 0.0;   // both eyes, at s2
    double s1 = 1.0;
    double s2 = 1.0;
    double throughput_bps = 0.0;  // measured from acknowledgements; 0 if nothing was sent
    // When the frame's request left and its periphery's last packet arrived (ms on the headset's
    // clock; 0 if nothing arrived): the one-way delay through server and link, queues included.
    double request_ms = 0.0;
    double arrival_ms = 0.0;
    // The periphery was requested but had not all arrived by the wait limit (shown late).
    bool periphery_late = false;
    // The periphery was not asked for: the headset's window of outstanding requests was full
    // (the link behind, qvr/core/request_window.h). The frame says nothing of T_remote.
    bool periphery_withheld = false;
    // What the server said it spent on the frame, from when it started on it to its last
    // layer's encode (FrameHeader::server_us; 0: not said, or the periphery was not all in).
    double server_ms = 0.0;
    // Streams of the periphery whose encoder opened a new canvas for it (FrameHeader::
    // kFlagNewCanvas): a key frame an e1 move caused, at the move or, for a canvas that shrank
    // after the layer stayed small, frames later.
    int new_canvas_streams = 0;
};

// The whole periphery of a frame that came after its wait limit (its frame was observed late).
struct LateArrival {
    int64_t index = 0;
    double middle_bytes = 0.0;  // both eyes
    double outer_bytes = 0.0;
    int new_canvas_streams = 0;
};

// Whether a frame is the session's start-up, whose timing reaches no policy's fits (the runtime's
// headset and its model alike; RunStats::warmup_frames also leaves these frames out, and its
// first --warmup-frames besides): the frames requested before any completed (frame < depth) and,
// for a frame that asked the server for layers, every frame up to the first UCA composed from
// them (first_composed < 0: none yet) — the server's first renders and key frames, the first use
// of every code path. One 80–140 ms start-up frame biased LIWC's 32-frame window by ~15 ms; the
// first composition alone took 450–580 ms at a quarter core (EPYC), and its frame taught LIWC's
// headset fit a slope that held e1 at 1° for 60 frames (docs/LIWC.md "Fits").
constexpr bool isStartUpFrame(int64_t frame, int64_t depth, bool remote_requested,
                              int64_t first_composed) {
    return frame < depth || (remote_requested && (first_composed < 0 || frame <= first_composed));
}

// The headset's own cost as LIWC reads it, the runtime's headset and its model alike: with frames
// in flight (depth > 1) its whole busy time competes with the server, so t_local_ms is that, with
// the fovea render's part apart (t_render_ms, the only part e1 moves); with one frame at a time,
// the fovea render alone. busy_ms ≤ 0: not measured (the session's first frame).
inline void setHeadsetTimes(FrameMeasurement& m, int64_t depth, double busy_ms, double render_ms) {
    const bool busy = depth > 1 && busy_ms > 0.0;
    m.t_local_ms = busy ? busy_ms : render_ms;
    m.t_render_ms = busy ? render_ms : 0.0;
}

// What the headset would measure of a frame rendered with `plan` at cost `cost`, the remote part
// having crossed a link of throughput_bps (0 if nothing was sent).
FrameMeasurement measureFrame(int64_t index, const LayerPlan& plan, const FrameCost& cost,
                              double throughput_bps);

class FoveaPolicy {
public:
    virtual ~FoveaPolicy() = default;
    virtual std::string_view name() const = 0;
    // Called before frame `frame` renders. Policies other than LIWC and the oracle must not
    // read the frame's per-ring data.
    virtual Decision decide(const WorkloadFrame& frame) = 0;
    // Called once frame `m.index` completes, in frame order.
    virtual void observe(const FrameMeasurement& m) = 0;
    // Called when the periphery of a frame observed as late (FrameMeasurement::periphery_late)
    // has all arrived after all: its streams' sizes, now whole.
    virtual void observeLateArrival(const LateArrival&) {}
};

// The paper's FFR: e1 fixed (5° by default).
class FixedPolicy final : public FoveaPolicy {
public:
    explicit FixedPolicy(double e1_deg = 5.0) : m_e1_deg(e1_deg) {}
    std::string_view name() const override { return "fixed"; }
    Decision decide(const WorkloadFrame& frame) override;
    void observe(const FrameMeasurement&) override {}

private:
    double m_e1_deg;
};

// The pure-software Q-VR of §6.1: picks e1 from previous frames' measured latencies, which
// reach it lag_frames late, scaling them to candidate sizes with the plan's pixel counts; no
// access to the frame's triangles before rendering.
struct SoftwareReactiveConfig {
    double e1_initial_deg = 5.0;
    double e1_min_deg = 1.0;
    double e1_max_deg = 90.0;
    double max_step_deg = 5.0;
    int lag_frames = 2;
};
std::unique_ptr<FoveaPolicy> makeSoftwareReactivePolicy(const WorkloadHeader& header,
                                                        SoftwareReactiveConfig config = {});

// The limit: knows each frame's true cost curve and picks the e1 minimising max(T_local,
// T_remote) on a fine grid, with no step limit.
std::unique_ptr<FoveaPolicy> makeOraclePolicy(const WorkloadHeader& header, const CostModel& truth,
                                              double e1_min_deg = 1.0, double e1_max_deg = 90.0);

}  // namespace qvr
