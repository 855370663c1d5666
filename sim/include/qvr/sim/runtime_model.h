// The runtime's pipeline as built (docs/RUNTIME.md), as a model beside the paper's (simulator.h):
// one headset core that runs the decision, the fovea render, every stream's decode and UCA in
// turn, frames in flight (1 or 2), a server with one render thread and a request queue of depth
// 2 where the newest request wins, a link that serialises the streams, vsync slots at the
// display rate, and the wait limit after which the display re-warps older layers (frame reuse).
// Its costs are this machine's, measured by `qvr calibrate` (RuntimeCosts); its metrics are the
// runtime's (telemetry.h): FPS of scan-out, MTP from pose sample to UCA end. docs/MODEL.md §8.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "qvr/core/canvas_policy.h"
#include "qvr/core/design.h"
#include "qvr/core/run_summary.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/sim/hardware.h"
#include "qvr/sim/network.h"
#include "qvr/workload/workload.h"

namespace qvr {

// The runtime model's settings: which pipeline `qvr sim` uses and the runtime's knobs.
struct RuntimeSimConfig {
    Design design = Design::Qvr;  // local, remote, ffr and fixed (fixed e1), sw, qvr/dfr (LIWC)
    double fixed_e1_deg = 5.0;    // the e1 of ffr and fixed
    RuntimeCosts costs;
    int pipeline_depth = 2;        // frames in flight (1 or 2); local always runs 1
    int server_queue = 2;          // the server's request queue; the newest request wins
    double wait_limit_ms = 250.0;  // remote layers later than this are late: the frame is reused
    int frames = 300;              // clamped to the trace's length
    // The summary leaves out the first frames, as the runtime's (DesignSummary::warmup_frames,
    // qvr run --warmup-frames): the frames are still simulated.
    int warmup_frames = 0;
    // LIWC learns the server's render + encode time (LiwcConfig::learn_remote_base), as in the
    // runtime.
    bool liwc_learn_remote_base = true;
    // The runtime's LIWC minimises the frame period max(L, R) (LiwcConfig::frame_period_objective);
    // false: Eq. 2's balance.
    bool liwc_frame_period_objective = true;
    // sw is the runtime's: LIWC's model fed reactively (LiwcConfig::reactive); false: the
    // simulator's software-reactive policy (makeSoftwareReactivePolicy).
    bool sw_uses_liwc = true;
    // Scan-out: false queues the composed image for its slot and goes on (the runtime's two-image
    // swapchain, VsyncPacer::queueForScanout); true blocks the headset until the slot.
    bool wait_for_vsync = false;
    // T_remote as the policies see it: to the last packet's arrival (the runtime's t_remote_ms),
    // or, when set, to the last stream decoded (t_remote_decoded_ms).
    bool t_remote_to_decode = false;
    // The headset's CFS quota (qvr run --headset-share): in every quota_period_ms it runs at
    // most headset_share of the period, at full speed, and waits for the next period once that
    // is spent; idle time spends none of it. 1: no quota.
    double headset_share = 1.0;
    double quota_period_ms = 10.0;
    // The run records its display video (qvr run --video): every frame's headset also pays
    // costs.scanout_record_ms, after the frame is queued for its slot (in the next frame's busy
    // time, as the runtime's DisplaySink is called).
    bool record_scanout = false;
    // The triangles one layer draws — kind 0 fovea (the whole frame for local and remote), 1
    // middle, 2 outer; eye 0 left, 1 right — for frame `frame` of the trace under `plan`: what
    // the renderer submits at its level of detail with the periphery's holes (render/renderer.h
    // layerTriangles), computed by the caller off the clock from the frame's pose. Empty: the
    // BVH rings of the trace (fovea: within e1 / 2; middle: within e2 / 2 / s1²; outer: all
    // / 2 / s2²), which see neither level of detail nor holes.
    std::function<double(int64_t frame, const LayerPlan& plan, int eye, int kind)> layer_triangles;
    // The fragments one eye's fovea (or whole-frame) pass shades for frame `frame` under `plan`
    // (RenderStats::fragment_invocations), < 0 where not known: the fovea law then charges its
    // pixels at the calibration's fragments per pixel. Empty: the trace's recorded fragments per
    // fovea pixel (WorkloadFrame::fovea_fragments_per_px, a qvr run's workload.jsonl) times the
    // pass's pixels where the frame has them. `qvr run` gives the counts its headset's own passes
    // made (docs/MODEL.md §9).
    std::function<double(int64_t frame, const LayerPlan& plan, int eye)> fovea_fragments;
    // The fragments the server's render of stream `stream` (2·eye + {middle or whole frame,
    // outer}) shades for frame `frame` in a layer of `pixels` pixels, < 0 where not known: the
    // server's law then charges the calibration's fragments per pixel. `qvr run` gives the
    // counts its server's own renders made (docs/MODEL.md §9). Empty: none known.
    std::function<double(int64_t frame, int stream, double pixels)> server_fragments;
};

// One frame, ms from the run's start, as the runtime's telemetry records it.
struct RuntimeFrame {
    int64_t index = 0;
    double e1_deg = 0.0;
    double pose_ms = 0.0;
    double request_ms = -1.0;
    double local_start_ms = 0.0, local_end_ms = 0.0;
    double remote_done_ms = -1.0;  // every stream decoded (−1: never, or not requested)
    double uca_start_ms = 0.0, uca_end_ms = 0.0;
    double display_ms = 0.0;
    double bytes = 0.0;
    double t_local_ms = 0.0;
    double t_remote_ms = 0.0;
    double headset_busy_ms = 0.0;
    double decision_ms = 0.0;
    double mtp_ms = 0.0;
    bool requested = false;
    bool served = false;    // the server rendered it (not pushed out of its queue)
    bool withheld = false;  // not asked: the request window was full (request_window.h)
    bool reused = false;
    // The server's render and encode time for its layers (before any co-run slowdown), and how
    // many of its streams were coded as key frames: per frame, beside server_frames.csv.
    double server_render_ms = 0.0, server_encode_ms = 0.0;
    int key_frames = 0;
};

// The run's statistics as the runtime's telemetry computes them (FrameSummarizer, the same
// start-up left out), and what only the model knows.
struct RuntimeSummary : RunStats {
    std::string design;  // its label: "qvr", "ffr", "fixed:10"
    int requests_dropped = 0;
    int requests_withheld = 0;         // the headset's request window was full (request_window.h)
    double server_busy_ms_mean = 0.0;  // render + encode per served frame
};

struct RuntimeRunResult {
    std::vector<RuntimeFrame> frames;
    RuntimeSummary summary;
};

// Each stream's encoder as the runtime's x264 streams run it (RuntimeCosts' canvas model): the
// canvas of CanvasPolicy, an IDR at the first frame, at every canvas change and every
// keyint_frames-th frame, padding beyond the snug canvas charged at padding_bits_ratio. Without a
// key-frame ratio (a calibration before version 7) every frame is the bits law's P-frame.
class StreamCodecModel {
public:
    static constexpr int kStreams = 4;  // eye × {middle or whole frame, outer}: 2·eye + kind
    static constexpr int kMaxSidePx = 8192;
    explicit StreamCodecModel(const RuntimeCosts& costs);
    bool enabled() const { return m_costs.keyframe_bits_ratio > 0.0; }
    // The bytes of `stream`'s next frame: a width×height layer whose P-frame in a snug canvas
    // takes p_bytes.
    double bytes(int stream, int width, int height, double p_bytes);
    bool lastWasKey() const { return m_last_key; }
    // The last frame opened a new encoder (the stream's first frame, a canvas change).
    bool lastOpenedCanvas() const { return m_last_opened; }
    // The last frame's canvas pixels (0 without the model): what the codec works on, and what
    // the encode and decode laws are per (`qvr calibrate` times them against their canvases).
    double lastCanvasPx() const { return m_last_canvas_px; }

private:
    struct State {
        CanvasPolicy canvas;
        int since_key = -1;  // frames since the last IDR; −1: none yet
    };
    RuntimeCosts m_costs;
    std::vector<State> m_streams;
    bool m_last_key = false;
    bool m_last_opened = false;
    double m_last_canvas_px = 0.0;
};

// One side's busy spans, ms, in time order and disjoint.
struct BusySpan {
    double start = 0.0, end = 0.0;
};

// When `work` ms of one side's work that starts at `start` ends, if it runs `slowdown` times
// slower while the other side is busy (`other`, disjoint and in time order) and at full speed
// otherwise.
double coRunEnd(double start, double work, const std::vector<BusySpan>& other, double slowdown);

// What the runtime's summary reads of a modelled frame; first_layers_ms is when the run's first
// remote layers were decoded (the start-up ends when they are on screen).
FrameSample runtimeFrameSample(const RuntimeFrame& f, double first_layers_ms);
// The summary of a replay's frames, config.warmup_frames and the start-up left out as the
// runtime's RunSummarizer leaves them (requests_dropped and server_busy_ms_mean are the replay's).
RuntimeSummary summarizeRuntimeFrames(const std::vector<RuntimeFrame>& frames,
                                      const RuntimeSimConfig& config);

// Replays `trace` through the runtime's pipeline on `link` (a constant rate or a trace; the
// caller gives it the link emulator's rate and no noise, efficiency 1: the payload share of a
// packet is applied here). Deterministic. With a co-running slowdown over 1 on either side
// (costs.headsetCoRun(), costs.serverCoRun()) the replay runs more than once: each pass slows the
// headset's work where the previous pass had the server busy, by the headset's factor, and the
// server's where it had the headset busy, by the server's (a fixed point of the two cores' mutual
// slowdown, docs/MODEL.md §11); `link` must then time every transfer from its start
// alone, as makeRuntimeLink's do.
RuntimeRunResult simulateRuntime(const WorkloadTrace& trace, const RuntimeSimConfig& config,
                                 Link& link);

// The link net's emulator (net/link_emulator.h) makes of a `qvr run --net` spec (the link grammar,
// qvr/core/link_spec.h), for this model: a named profile or "rate:MBPS" at its rate, or
// "trace:PATH[@MBPS]" (a Mahimahi trace at its recorded mean unless MBPS is given); of the
// ",key=value" options delay_ms is used (one way; *delay_ms) and the rest (loss, jitter, queue,
// faults) are not modelled; "none" (no rate) is refused. No noise: the emulator has none; packet
// headers are charged by the model.
Expected<std::unique_ptr<Link>> makeRuntimeLink(const std::string& spec, double* delay_ms);

// The triangle feature of one server layer: the BVH's triangles in the layer's cone (both eyes)
// halved for one eye and divided by the layer's scale squared — with a level of detail bound in
// the layer's own pixels, a layer s times coarser draws about s² times fewer of a dense scene's
// triangles. `qvr calibrate` fits server_render on it, the model charges it.
double serverLayerTriangles(double cone_triangles_both_eyes, double scale);

}  // namespace qvr
