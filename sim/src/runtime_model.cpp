// The runtime's pipeline (runtime/src/headset_client.cpp, render_server.cpp) as events on three
// timelines: the headset's one core, the server's render thread and the link. The headset runs
// the runtime's loop literally — prepare frames up to the pipeline depth ahead (pose, decision,
// request), then finish the oldest (fovea render, wait for its streams while decoding whatever
// arrives, UCA, vsync) — and the server is advanced lazily up to the headset's clock, which is
// exact because only the headset adds requests. docs/MODEL.md §8.
#include "qvr/sim/runtime_model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <memory>
#include <numeric>

#include "qvr/controller/aimd.h"
#include "qvr/controller/liwc.h"
#include "qvr/controller/policy.h"
#include "qvr/core/canvas_policy.h"
#include "qvr/core/link_spec.h"
#include "qvr/core/request_window.h"
#include "qvr/core/silence.h"
#include "qvr/core/throughput_estimator.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {

namespace {

// One eye's fovea fragments from the trace's recorded fragments per fovea pixel; −1 (the law's
// mean) where none is recorded, and for a whole-frame pass, whose depth complexity the fovea's
// does not tell.
double recordedFragments(const WorkloadFrame& wf, double pixels, bool whole_frame) {
    return wf.fovea_fragments_per_px >= 0.0 && !whole_frame ? wf.fovea_fragments_per_px * pixels
                                                            : -1.0;
}

// The frames the runtime's headset holds pending (runtime kMaxPendingFrames).
constexpr int64_t kPendingFrames = 64;

struct Stream {
    int64_t frame = 0;
    double send_ms = 0.0;  // first packet on the link
    double rx_ms = 0.0;    // last packet arrived
    double payload_bytes = 0.0;
    double pixels = 0.0;  // pixels the decoder works on (the canvas)
    bool decoded = false;
};

struct FrameState {
    LayerPlan plan;
    int expected = 0;  // streams
    int decoded = 0;
    double last_rx_ms = 0.0;
    // When the server could start on it: its request, or the last packet of a frame requested
    // before it, whichever came later (the runtime's PendingFrame::service_start_ns).
    double service_start_ms = 0.0;
    double received_bytes = 0.0;
    double middle_bytes = 0.0, outer_bytes = 0.0;
    bool served = false;
    double server_render_ms = 0.0, server_encode_ms = 0.0;  // the server's work on it
    int key_frames = 0;                                     // its streams coded as IDRs
    int new_canvases = 0;    // of which a new encoder opened (FrameMeasurement::new_canvas_streams)
    double server_ms = 0.0;  // from the start of its service to its last layer's encode
    bool closed = false;     // its pending entry is gone: LIWC does not see later streams
    bool observed_late = false;  // LIWC learnt it before its periphery came (LateArrival)
    bool withheld = false;       // not asked for: the request window was full
};

// A layer the server renders and sends: its pixels, the triangles in its view, its bytes.
struct LayerJob {
    double pixels = 0.0;
    double triangles = 0.0;
    double bytes = 0.0;
    bool middle = true;
    int stream = 0;  // eye × {middle or whole frame, outer}: the encoder it goes through
    int width = 0, height = 0;
};

}  // namespace

StreamCodecModel::StreamCodecModel(const RuntimeCosts& costs) : m_costs(costs) {
    if (enabled())
        for (int k = 0; k < kStreams; ++k)
            m_streams.push_back({CanvasPolicy(costs.canvas_align_px, costs.canvas_headroom,
                                              costs.canvas_shrink_ratio,
                                              costs.canvas_shrink_after_frames, kMaxSidePx),
                                 -1});
}

double StreamCodecModel::bytes(int stream, int width, int height, double p_bytes) {
    m_last_key = false;
    m_last_opened = false;
    m_last_canvas_px = 0.0;
    if (!enabled() || width < 1 || height < 1 || stream < 0 || stream >= kStreams)
        return p_bytes;
    State& st = m_streams[static_cast<size_t>(stream)];
    const bool key_due =
        st.since_key >= 0 && m_costs.keyint_frames > 0 && st.since_key + 1 >= m_costs.keyint_frames;
    const CanvasSize canvas =
        st.canvas.next(std::min(width, kMaxSidePx), std::min(height, kMaxSidePx), key_due);
    const CanvasSize snug =
        st.canvas.snugFor(std::min(width, kMaxSidePx), std::min(height, kMaxSidePx));
    // The bits law is a P-frame's in a snug canvas: each pixel beyond it costs padding_bits_ratio
    // of a layer pixel's bits (fewer when the layer grew into its headroom).
    m_last_canvas_px = double(canvas.width) * double(canvas.height);
    const double extra =
        m_last_canvas_px / std::max(1.0, double(snug.width) * double(snug.height)) - 1.0;
    const double p = p_bytes * std::max(0.5, 1.0 + m_costs.padding_bits_ratio * extra);
    const bool opened = st.since_key < 0 || st.canvas.changed();  // a new encoder
    const bool periodic = !opened && key_due;
    st.since_key = opened || periodic ? 0 : st.since_key + 1;
    m_last_key = opened || periodic;
    m_last_opened = opened;
    if (!m_last_key)
        return p;
    if (periodic && m_costs.keyframe_periodic_bits_ratio > 0.0)
        return p * m_costs.keyframe_periodic_bits_ratio;
    const bool outer = stream % 2 == 1;
    return p * (outer && m_costs.keyframe_outer_bits_ratio > 0.0 ? m_costs.keyframe_outer_bits_ratio
                                                                 : m_costs.keyframe_bits_ratio);
}

Expected<std::unique_ptr<Link>> makeRuntimeLink(const std::string& spec, double* delay_ms) {
    if (delay_ms)
        *delay_ms = 0.0;
    auto link = loadLinkSpec(spec);
    if (!link)
        return makeError(link.error());
    if (delay_ms)
        *delay_ms = link->delay_ms;
    if (link->trace) {
        const double target_bps =
            link->trace_target_bps > 0.0 ? link->trace_target_bps : link->trace->meanBps();
        return std::unique_ptr<Link>(
            std::make_unique<TraceLink>(link->name, link->trace, target_bps, 1.0, RadioPower{}));
    }
    if (link->rate_bps > 0.0)
        return std::unique_ptr<Link>(
            std::make_unique<NoisyLink>(link->name, link->rate_bps, 1.0,
                                        std::numeric_limits<double>::infinity(), RadioPower{}, 1));
    return makeError("link '" + spec +
                     "': the runtime model needs a rate or a trace (wifi, lte or 4g, 5g, "
                     "rate:MBPS, trace:PATH[@MBPS])");
}

FrameSample runtimeFrameSample(const RuntimeFrame& f, double first_layers_ms) {
    FrameSample x;
    x.pose_ms = f.pose_ms;
    x.display_ms = f.display_ms;
    x.mtp_ms = f.mtp_ms;
    x.bytes = f.bytes;
    x.e1_deg = f.e1_deg;
    x.t_local_ms = f.t_local_ms;
    x.t_remote_ms = f.t_remote_ms;
    x.headset_busy_ms = f.headset_busy_ms;
    x.remote_requested = f.requested;
    x.remote_withheld = f.withheld;
    // The runtime's shown_frame ≥ 0: the server's first layers were on screen by its UCA.
    x.remote_shown = f.uca_start_ms >= first_layers_ms;
    x.reused = f.reused;
    return x;
}

RuntimeSummary summarizeRuntimeFrames(const std::vector<RuntimeFrame>& frames,
                                      const RuntimeSimConfig& config) {
    double first_layers_ms = std::numeric_limits<double>::infinity();
    for (const RuntimeFrame& f : frames)
        if (f.remote_done_ms >= 0.0)
            first_layers_ms = std::min(first_layers_ms, f.remote_done_ms);
    FrameSummarizer summarizer(config.warmup_frames);
    for (const RuntimeFrame& f : frames)
        summarizer.add(runtimeFrameSample(f, first_layers_ms));
    RuntimeSummary s;
    static_cast<RunStats&>(s) = summarizer.finish();
    s.design = designLabel(config.design, config.fixed_e1_deg);
    return s;
}

double serverLayerTriangles(double cone_triangles_both_eyes, double scale) {
    const double s = std::max(scale, 1.0);
    return cone_triangles_both_eyes / 2.0 / (s * s);
}

double coRunEnd(double start, double work, const std::vector<BusySpan>& other, double slowdown) {
    if (!(work > 0.0))
        return start;
    if (!(slowdown > 1.0) || other.empty())
        return start + work;
    // The first span still running at `start`.
    auto it = std::upper_bound(other.begin(), other.end(), start,
                               [](double t, const BusySpan& b) { return t < b.end; });
    double t = start;
    double left = work;
    for (; it != other.end(); ++it) {
        if (t < it->start) {  // alone until the other side's next span
            if (left <= it->start - t)
                return t + left;
            left -= it->start - t;
            t = it->start;
        }
        const double shared = it->end - t;  // both busy: 1 / slowdown of the pace
        if (left * slowdown <= shared)
            return t + left * slowdown;
        left -= shared / slowdown;
        t = it->end;
    }
    return t + left;
}

namespace {

// What one pass of the replay had each side busy with (for the next pass's co-running).
struct CoRunLog {
    std::vector<BusySpan> headset, server;
};

void logSpan(std::vector<BusySpan>& spans, double start, double end) {
    if (!(end > start))
        return;
    if (!spans.empty() && start <= spans.back().end) {  // touching or (rounding) overlapping
        spans.back().end = std::max(spans.back().end, end);
        return;
    }
    spans.push_back({start, end});
}

// The co-running passes stop when no frame's scan-out-ready time (UCA's end) moves by more than
// kCoRunSettledMs from the pass before, or after kCoRunMaxPasses.
constexpr double kCoRunSettledMs = 0.01;
constexpr int kCoRunMaxPasses = 24;

// One pass of the replay: the headset's core, the server's render thread and the link as
// events, the headset running the runtime's loop and the server advanced lazily to its clock.
class PassReplay {
public:
    PassReplay(const WorkloadTrace& trace, const RuntimeSimConfig& config, Link& link,
               const CoRunLog* previous, CoRunLog* log)
        : m_trace(trace),
          m_header(trace.header),
          m_config(config),
          m_costs(config.costs),
          m_traits(traitsOf(config.design)),
          m_link(link),
          m_log(log),
          m_local_only(m_traits.split == Split::LocalOnly),
          m_whole_frame(m_traits.split == Split::RemoteOnly),
          m_liwc(m_traits.policy == "liwc"),
          m_sw(m_traits.policy == "sw"),
          m_sw_liwc(m_sw && config.sw_uses_liwc),
          m_planner(m_header.profile),
          m_eye_px(double(m_header.profile.width_px) * double(m_header.profile.height_px)),
          m_period_ms(1000.0 / std::max(1.0, m_header.profile.refresh_hz)),
          m_n_frames(std::clamp<int>(config.frames, 0, static_cast<int>(trace.frames.size()))),
          m_depth(m_local_only ? 1 : static_cast<size_t>(std::clamp(config.pipeline_depth, 1, 4))),
          m_queue_cap(static_cast<size_t>(std::max(config.server_queue, 1))),
          // Work on one side runs slower where the previous pass had the other side busy.
          m_headset_slowdown(previous ? config.costs.headsetCoRun() : 1.0),
          m_server_slowdown(previous ? config.costs.serverCoRun() : 1.0),
          m_server_spans(previous ? previous->server : kNoSpans),
          m_headset_spans(previous ? previous->headset : kNoSpans),
          m_codecs(config.costs) {
        makePolicy();
        m_result.frames.resize(static_cast<size_t>(m_n_frames));
        m_state.resize(static_cast<size_t>(m_n_frames));
    }

    RuntimeRunResult run();

private:
    struct Request {
        int64_t frame;
        double arrive_ms;
    };
    static inline const std::vector<BusySpan> kNoSpans;

    void makePolicy();
    void work(double ms);
    double throttledEnd(double start, double run_ms);
    double serverWork(double start, double ms);
    double bitsPerPx(const WorkloadFrame& wf, double scale, bool outer) const;
    double drawn(int64_t j, const LayerPlan& plan, int eye, int kind, double rings_both_eyes,
                 double scale) const;
    std::vector<LayerJob> layerJobs(int64_t j, const FrameState& fs, const WorkloadFrame& wf) const;
    double sendLayer(int64_t j, FrameState& fs, LayerJob& job, double t);
    void serve(int64_t j, double start);
    void advanceServer(double until);
    void decodeNext();
    void pump();
    size_t outstandingRequests(int64_t i) const;
    double lastPacketMs() const;
    void decideLayers(FrameState& fs, RuntimeFrame& rf, const WorkloadFrame& wf);
    void prepare(int64_t i);
    void renderFovea(int64_t i);
    bool waitForStreams(int64_t i);
    void composeAndScanOut(int64_t i, bool have_current);
    void learn(int64_t i);
    void finish(int64_t i);

    const WorkloadTrace& m_trace;
    const WorkloadHeader& m_header;
    const RuntimeSimConfig& m_config;
    const RuntimeCosts& m_costs;
    const DesignTraits& m_traits;
    Link& m_link;
    CoRunLog* m_log;
    const bool m_local_only, m_whole_frame, m_liwc, m_sw, m_sw_liwc;
    const LayerPlanner m_planner;
    const double m_eye_px;
    const double m_period_ms;
    const int m_n_frames;
    const size_t m_depth;
    const size_t m_queue_cap;
    const double m_headset_slowdown, m_server_slowdown;
    const std::vector<BusySpan>& m_server_spans;
    const std::vector<BusySpan>& m_headset_spans;
    // Each stream's encoder, its canvas and key frames (docs/MODEL.md §10).
    StreamCodecModel m_codecs;

    LiwcPolicy* m_link_aware = nullptr;  // the policy that reads the acks at decision time
    std::unique_ptr<FoveaPolicy> m_policy;
    RuntimeRunResult m_result;
    std::vector<FrameState> m_state;
    std::vector<Stream> m_streams;  // every stream sent, in rx order (the link keeps order)

    // Headset core.
    double m_hs = 0.0;
    int64_t m_quota_period = -1;  // the CFS period m_quota_used_ms was spent in
    double m_quota_used_ms = 0.0;
    double m_busy = 0.0;  // busy time since the previous frame finished
    double m_last_e1_deg = 5.0;
    double m_last_complete_rx_ms = 0.0;
    int64_t m_newest_complete = -1;  // the newest frame whose periphery all came
    // The streams the headset took from the transport (the session's start, 0 ms, before any):
    // a server silent for a whole wait limit (or twice its spacing, if longer) makes the runtime
    // wait one refresh instead.
    SilenceDetector m_silence;
    int64_t m_last_slot = -1;  // the newest scan-out's vsync slot index
    // The server's estimate from the acks (the runtime's, reported to the headset): a stream is
    // handed to the link when encoded and acknowledged when its last packet arrives.
    ThroughputEstimator m_link_estimate;
    // Server and link.
    std::deque<Request> m_queue;
    double m_server_free = 0.0, m_link_free = 0.0, m_server_busy_total = 0.0;
    int64_t m_first_composed = -1;  // the first frame composed from the server's layers
    int m_served_frames = 0;
    size_t m_next_undecoded = 0;
};

// The runtime's policies (runtime/src/headset_client.cpp liwcConfig): qvr is LIWC with the
// frame-period objective, sw the same model fed reactively, aimd EyeNexus's controller.
void PassReplay::makePolicy() {
    auto runtimeLiwc = [&](bool reactive) {
        LiwcConfig lc;
        lc.learn_remote_base = m_config.liwc_learn_remote_base;
        lc.frame_period_objective = m_config.liwc_frame_period_objective;
        lc.frames_in_flight = static_cast<int>(m_depth);
        lc.reactive = reactive;
        return std::make_unique<LiwcPolicy>(m_header, lc);
    };
    if (m_liwc) {
        auto p = runtimeLiwc(false);
        p->setHeadsetShare(m_config.headset_share);  // as the runtime reads its cgroup's
        m_link_aware = p.get();
        m_policy = std::move(p);
    } else if (m_sw_liwc) {
        auto p = runtimeLiwc(true);
        p->setHeadsetShare(m_config.headset_share);
        m_policy = std::move(p);
    } else if (m_sw) {
        m_policy = makeSoftwareReactivePolicy(m_header);
    } else if (m_traits.policy == "fixed") {
        m_policy = std::make_unique<FixedPolicy>(m_config.fixed_e1_deg);
    } else if (m_traits.policy == "aimd") {
        m_policy = makeAimdPolicy(m_header);
    }
}

void PassReplay::work(double ms) {
    double end = coRunEnd(m_hs, ms, m_server_spans, m_headset_slowdown);
    if (m_config.headset_share < 1.0)
        end = throttledEnd(m_hs, end - m_hs);
    if (m_log)
        logSpan(m_log->headset, m_hs, end);
    m_busy += end - m_hs;
    m_hs = end;
}

// CFS bandwidth control (the kernel's sched-bwc): the headset's group gets share × period of
// CPU in each period and is throttled to the period's end once it has used that. Work that fits
// in a period's budget runs at full speed; the headset's waits spend none.
double PassReplay::throttledEnd(double start, double run_ms) {
    const double period = std::max(m_config.quota_period_ms, 0.1);
    const double budget = std::clamp(m_config.headset_share, 1e-3, 1.0) * period;
    double t = start;
    // The headset's clock never goes back: periods are counted from the one last spent in.
    int64_t k = std::max(m_quota_period, static_cast<int64_t>(std::floor(t / period)));
    while (t >= double(k + 1) * period)
        ++k;
    while (run_ms > 1e-12) {
        if (k != m_quota_period) {
            m_quota_period = k;
            m_quota_used_ms = 0.0;
        }
        const double period_end = double(k + 1) * period;
        const double run = std::min({run_ms, budget - m_quota_used_ms, period_end - t});
        if (run > 0.0) {
            t += run;
            m_quota_used_ms += run;
            run_ms -= run;
        }
        if (run_ms > 1e-12 && (m_quota_used_ms >= budget - 1e-12 || t >= period_end - 1e-12)) {
            t = std::max(t, period_end);  // throttled, or the period ran out: the next one
            ++k;
        }
    }
    return t;
}

double PassReplay::serverWork(double start, double ms) {
    const double end = coRunEnd(start, ms, m_headset_spans, m_server_slowdown);
    if (m_log)
        logSpan(m_log->server, start, end);
    return end;
}

// Bits per layer pixel at scale s: the calibration's law when it has one, else the trace's.
double PassReplay::bitsPerPx(const WorkloadFrame& wf, double scale, bool outer) const {
    if (m_costs.bits_per_px_at_1 > 0.0)
        return m_costs.bitsPerPx(scale, outer);
    return bitsPerPixelAt(m_header, wf, scale);
}

// Pixels UCA reads (every layer of both eyes at its own resolution).
double layerPixels(const LayerPlan& plan) {
    double px = 0.0;
    for (const EyeLayers& e : plan.eyes)
        px += double(e.fovea.pixels() + e.middle.pixels() + e.outer.pixels());
    return px;
}

// Triangles a layer draws (kind 0 fovea, 1 middle, 2 outer; eye 0/1): the caller's count of what
// the renderer submits when it has one, else the BVH rings of the trace.
double PassReplay::drawn(int64_t j, const LayerPlan& plan, int eye, int kind,
                         double rings_both_eyes, double scale) const {
    if (m_config.layer_triangles)
        return m_config.layer_triangles(j, plan, eye, kind);
    return kind == 0 ? rings_both_eyes / 2.0 : serverLayerTriangles(rings_both_eyes, scale);
}

// The layers the server renders and sends for frame j, their bytes before the codec model.
std::vector<LayerJob> PassReplay::layerJobs(int64_t j, const FrameState& fs,
                                            const WorkloadFrame& wf) const {
    const double total_tris = sumTotal(wf.triangles_per_ring);
    std::vector<LayerJob> jobs;
    if (m_whole_frame) {
        const double bpp = m_costs.bits_per_px_at_1 > 0.0 && m_costs.bits_full_frame_per_px > 0.0
                               ? m_costs.bits_full_frame_per_px
                               : bitsPerPx(wf, 1.0, false);
        const double bytes = bpp * m_eye_px / 8.0;
        // The whole frame at scale 1 is the all-local plan's fovea view, no hole.
        for (int eye = 0; eye < 2; ++eye)
            jobs.push_back({m_eye_px, drawn(j, fs.plan, eye, 0, total_tris, 1.0), bytes, true,
                            eye * 2, m_header.profile.width_px, m_header.profile.height_px});
        return jobs;
    }
    // The calibration's own frame j, where this frame's head pose is the one it coded: its bits
    // over the law (RuntimeCosts::bitsFrameFactor).
    const uint32_t key = m_costs.bits_frame_key.empty() ? 0u : frameContentKey(wf.head);
    const double f_mid =
        m_costs.bits_per_px_at_1 > 0.0 ? m_costs.bitsFrameFactor(size_t(j), key, false) : 1.0;
    const double f_out =
        m_costs.bits_per_px_at_1 > 0.0 ? m_costs.bitsFrameFactor(size_t(j), key, true) : 1.0;
    const PeripheryBytes pb = {
        2.0 * double(fs.plan.middle_pixels) * bitsPerPx(wf, fs.plan.s1, false) * f_mid / 8.0,
        2.0 * double(fs.plan.outer_pixels) * bitsPerPx(wf, fs.plan.s2, true) * f_out / 8.0};
    const double mid_tris = sumWithinDeg(wf.triangles_per_ring, m_header.ring_deg, fs.plan.e2_deg);
    for (int eye = 0; eye < 2; ++eye) {
        const EyeLayers& e = fs.plan.eyes[static_cast<size_t>(eye)];
        if (!e.middle.empty())
            jobs.push_back({double(e.middle.pixels()),
                            drawn(j, fs.plan, eye, 1, mid_tris, e.middle.scale), pb.middle / 2.0,
                            true, eye * 2, e.middle.width_px, e.middle.height_px});
        if (!e.outer.empty())
            jobs.push_back({double(e.outer.pixels()),
                            drawn(j, fs.plan, eye, 2, total_tris, e.outer.scale), pb.outer / 2.0,
                            false, eye * 2 + 1, e.outer.width_px, e.outer.height_px});
    }
    return jobs;
}

// Renders and encodes one layer from t on the server and sends it; returns the server's time
// after it.
double PassReplay::sendLayer(int64_t j, FrameState& fs, LayerJob& job, double t) {
    job.bytes = m_codecs.bytes(job.stream, job.width, job.height, job.bytes);
    // The codec works on the whole canvas, and its encode and decode laws are per canvas pixel:
    // the calibration times each against its encoder's canvas (the snug canvas's own headroom
    // and alignment make it 1.2-1.4x a layer's pixels). Without the canvas model, the layer.
    const double coded_px = m_codecs.lastCanvasPx() > 0.0 ? m_codecs.lastCanvasPx() : job.pixels;
    const double frags =
        m_config.server_fragments ? m_config.server_fragments(j, job.stream, job.pixels) : -1.0;
    const double render = m_whole_frame
                              ? m_costs.server_render.atFullFrame(job.pixels, job.triangles, frags)
                              : m_costs.server_render.at(job.pixels, job.triangles, frags);
    // remote's whole frame: the encode's own scale, measured on whole frames, as the render's.
    const double encode = m_whole_frame ? m_costs.encode.atFullFrame(coded_px, 0.0)
                                        : m_costs.encode.at(coded_px, 0.0);
    fs.server_render_ms += render;
    fs.server_encode_ms += encode;
    fs.key_frames += m_codecs.lastWasKey() ? 1 : 0;
    fs.new_canvases += m_codecs.lastOpenedCanvas() ? 1 : 0;
    const double layer_start = t;
    t = serverWork(t, render + encode);
    m_server_busy_total += t - layer_start;
    const double send = std::max(m_link_free, t);
    const LinkTransfer tr = m_link.transfer(send, job.bytes / m_costs.payloadShare());
    m_link_free = send + tr.duration_ms;
    Stream s;
    s.frame = j;
    s.send_ms = send;
    s.rx_ms = m_link_free + m_costs.link_delay_ms;
    s.payload_bytes = job.bytes;
    s.pixels = coded_px;
    m_streams.push_back(s);
    m_link_estimate.onSend(static_cast<uint32_t>(j), static_cast<int64_t>(job.bytes),
                           static_cast<int64_t>(t * 1e6));
    if (job.middle)
        fs.middle_bytes += job.bytes;
    else
        fs.outer_bytes += job.bytes;
    return t;
}

// Renders, encodes and sends frame j's layers from `start`.
void PassReplay::serve(int64_t j, double start) {
    FrameState& fs = m_state[static_cast<size_t>(j)];
    const WorkloadFrame& wf = m_trace.frames[static_cast<size_t>(j)];
    fs.served = true;
    ++m_served_frames;
    double t = serverWork(start, m_costs.server_frame_ms);
    std::vector<LayerJob> jobs = layerJobs(j, fs, wf);
    for (LayerJob& job : jobs)
        t = sendLayer(j, fs, job, t);
    fs.server_ms = t - start;
    m_server_free = t;
}

// Starts every queued request the server would have started by `until`.
void PassReplay::advanceServer(double until) {
    while (!m_queue.empty()) {
        const double start = std::max(m_server_free, m_queue.front().arrive_ms);
        if (start > until)
            break;
        const int64_t j = m_queue.front().frame;
        m_queue.pop_front();
        serve(j, start);
    }
}

// Decodes the next received stream (the transport hands them over in arrival order).
void PassReplay::decodeNext() {
    Stream& s = m_streams[m_next_undecoded++];
    m_hs = std::max(m_hs, s.rx_ms);
    work(m_costs.decode.at(s.pixels, 0.0));
    s.decoded = true;
    m_link_estimate.onAck(static_cast<uint32_t>(s.frame), static_cast<int64_t>(s.payload_bytes),
                          static_cast<int64_t>(s.rx_ms * 1e6));
    FrameState& fs = m_state[static_cast<size_t>(s.frame)];
    RuntimeFrame& rf = m_result.frames[static_cast<size_t>(s.frame)];
    fs.last_rx_ms = std::max(fs.last_rx_ms, s.rx_ms);
    m_silence.onStream(m_hs);
    // A frame's bytes are what arrived for it, whenever (the runtime counts a late frame's
    // streams too, until the frame is retired). What LIWC observes is only what came while the
    // frame held its pending entry: until the frame after it was shown.
    rf.bytes += s.payload_bytes;
    if (!fs.closed)
        fs.received_bytes += s.payload_bytes;
    if (++fs.decoded == fs.expected) {
        if (fs.observed_late && !fs.closed)
            m_policy->observeLateArrival(
                {s.frame, fs.middle_bytes, fs.outer_bytes, fs.new_canvases});
        rf.remote_done_ms = m_hs;
        m_last_complete_rx_ms = std::max(m_last_complete_rx_ms, fs.last_rx_ms);
        m_newest_complete = std::max(m_newest_complete, s.frame);
        // Frames requested after it waited for it; not the frame itself, nor any before it (a
        // frame whose streams were decoded before its own wait kept its remote time).
        // (A frame not yet prepared has no request; the runtime holds at most kPendingFrames.)
        const size_t end = std::min(m_state.size(), size_t(s.frame) + 1 + kPendingFrames);
        for (size_t k = size_t(s.frame) + 1; k < end; ++k)
            if (m_result.frames[k].requested)
                m_state[k].service_start_ms = std::max(m_state[k].service_start_ms, fs.last_rx_ms);
    }
}

// Takes what has arrived by now (pumpNetwork(0)).
void PassReplay::pump() {
    for (;;) {
        advanceServer(m_hs);
        if (m_next_undecoded >= m_streams.size() || m_streams[m_next_undecoded].rx_ms > m_hs)
            break;
        decodeNext();
    }
}

// Step 2: the frame's plan and the streams it waits for.
void PassReplay::decideLayers(FrameState& fs, RuntimeFrame& rf, const WorkloadFrame& wf) {
    if (m_local_only) {
        fs.plan = m_planner.plan(wf.gaze, 180.0);
        rf.e1_deg = fs.plan.cover_deg;
    } else if (m_whole_frame) {
        fs.plan = m_planner.plan(wf.gaze, 180.0);
        fs.expected = 2;
        rf.e1_deg = 0.0;
    } else {
        if (m_link_aware)
            m_link_aware->setLinkEstimate(m_link_estimate.throughputBps());
        const Decision d = m_policy->decide(wf);
        m_last_e1_deg = d.e1_deg;
        fs.plan = m_planner.plan(wf.gaze, d.e1_deg);
        rf.e1_deg = fs.plan.e1_deg;
        for (const EyeLayers& e : fs.plan.eyes)
            fs.expected += (e.middle.empty() ? 0 : 1) + (e.outer.empty() ? 0 : 1);
    }
}

// Steps 1–3.
void PassReplay::prepare(int64_t i) {
    RuntimeFrame& rf = m_result.frames[static_cast<size_t>(i)];
    FrameState& fs = m_state[static_cast<size_t>(i)];
    const WorkloadFrame& wf = m_trace.frames[static_cast<size_t>(i)];
    rf.index = wf.index;
    rf.pose_ms = m_hs;
    if (!m_local_only)
        pump();
    const double decision_start = m_hs;
    if (m_liwc || m_sw_liwc) {
        // The ring counts (the runtime probes for qvr and sw): the draw clusters' cost the same
        // at every e1 (a calibration fits no triangle slope); the BVH's reach e1 + 6°.
        const double counted = sumWithinDeg(wf.triangles_per_ring, m_header.ring_deg,
                                            m_last_e1_deg + 6.0 + m_header.ring_deg);
        work(m_costs.decision.at(0.0, counted));
    }
    decideLayers(fs, rf, wf);
    rf.decision_ms = m_hs - decision_start;
    fs.withheld = fs.expected > 0 && outstandingRequests(i) >= RequestWindow::window(m_depth);
    rf.withheld = fs.withheld;
    if (fs.withheld)
        ++m_result.summary.requests_withheld;
    if (fs.expected > 0 && !fs.withheld) {
        rf.requested = true;
        rf.request_ms = m_hs;
        fs.service_start_ms = std::max(m_hs, m_last_complete_rx_ms);
        advanceServer(m_hs);
        m_queue.push_back({i, m_hs});
        while (m_queue.size() > m_queue_cap) {
            m_queue.pop_front();
            ++m_result.summary.requests_dropped;
        }
    }
}

// When the newest media packet came: now while a stream is on the link, else the last stream's
// arrival (−1: none yet).
double PassReplay::lastPacketMs() const {
    if (m_next_undecoded < m_streams.size() && m_streams[m_next_undecoded].send_ms <= m_hs)
        return m_hs;
    return m_next_undecoded > 0 ? m_streams[m_next_undecoded - 1].rx_ms : -1.0;
}

// The requests still outstanding (qvr/core/request_window.h), among the frames the runtime would
// still hold pending.
size_t PassReplay::outstandingRequests(int64_t i) const {
    const double last_packet_ms = lastPacketMs();
    size_t n = 0;
    for (int64_t k = i - 1; k > m_newest_complete && k >= i - kPendingFrames; --k) {
        const FrameState& fs = m_state[static_cast<size_t>(k)];
        const RuntimeFrame& rf = m_result.frames[static_cast<size_t>(k)];
        n += rf.requested && fs.decoded < fs.expected &&
             RequestWindow::holds(rf.request_ms, m_hs, last_packet_ms, m_config.wait_limit_ms);
    }
    return n;
}

// 4. The fovea (the whole frame for local), one pass per eye.
void PassReplay::renderFovea(int64_t i) {
    RuntimeFrame& rf = m_result.frames[static_cast<size_t>(i)];
    const FrameState& fs = m_state[static_cast<size_t>(i)];
    const WorkloadFrame& wf = m_trace.frames[static_cast<size_t>(i)];
    rf.local_start_ms = m_hs;
    if (!m_whole_frame) {
        const double tris =
            m_local_only ? sumTotal(wf.triangles_per_ring)
                         : sumWithinDeg(wf.triangles_per_ring, m_header.ring_deg, fs.plan.e1_deg);
        for (int eye = 0; eye < 2; ++eye) {
            const EyeLayers& e = fs.plan.eyes[static_cast<size_t>(eye)];
            if (e.fovea.empty())
                continue;
            const double px = double(e.fovea.pixels());
            const double drawn_tris = drawn(i, fs.plan, eye, 0, tris, 1.0);
            const double frags = m_config.fovea_fragments
                                     ? m_config.fovea_fragments(i, fs.plan, eye)
                                     : recordedFragments(wf, px, m_local_only);
            work(m_local_only ? m_costs.fovea.atFullFrame(px, drawn_tris, frags)
                              : m_costs.fovea.at(px, drawn_tris, frags));
        }
    }
    rf.local_end_ms = m_hs;
    rf.t_local_ms = rf.local_end_ms - rf.local_start_ms;
}

// 5. Waits for this frame's streams, decoding whatever arrives; whether they all came.
bool PassReplay::waitForStreams(int64_t i) {
    RuntimeFrame& rf = m_result.frames[static_cast<size_t>(i)];
    FrameState& fs = m_state[static_cast<size_t>(i)];
    const double service_start = std::max(rf.request_ms, fs.service_start_ms);
    // A server that has delivered no stream for a whole wait limit: wait one refresh (the
    // runtime's silent_server_frames, docs/RUNTIME.md step 5).
    const bool silent = m_silence.silent(rf.local_end_ms, m_config.wait_limit_ms);
    const double deadline =
        silent ? std::max(rf.local_end_ms, rf.pose_ms) + m_period_ms
               : std::max({rf.local_end_ms, rf.pose_ms, service_start}) + m_config.wait_limit_ms;
    for (;;) {
        advanceServer(deadline);  // no request is sent while the headset waits
        if (fs.decoded == fs.expected || m_hs >= deadline)
            break;
        if (m_next_undecoded >= m_streams.size() || m_streams[m_next_undecoded].rx_ms >= deadline) {
            m_hs = std::max(m_hs, deadline);
            break;
        }
        decodeNext();
    }
    const bool have_current = fs.decoded == fs.expected;
    // To the last packet's arrival, as the runtime measures it (not to the decode, which waits
    // behind the headset's own work); censored at the wait for a late frame.
    const double end =
        have_current ? (m_config.t_remote_to_decode ? rf.remote_done_ms : fs.last_rx_ms) : m_hs;
    rf.t_remote_ms = std::max(0.0, end - service_start);
    return have_current;
}

// 6–7. UCA with the newest pose (a late frame re-warps older layers), then scan-out.
void PassReplay::composeAndScanOut(int64_t i, bool have_current) {
    RuntimeFrame& rf = m_result.frames[static_cast<size_t>(i)];
    const FrameState& fs = m_state[static_cast<size_t>(i)];
    rf.reused = !have_current;
    // The runtime drops the pending entries of frames shown before this one.
    for (int64_t k = i - 1; k >= 0 && !m_state[static_cast<size_t>(k)].closed; --k)
        m_state[static_cast<size_t>(k)].closed = true;
    rf.uca_start_ms = m_hs;
    // What UCA reads: this frame's layers, or for a reused frame the older ones it re-warps
    // (same plan shape).
    const double uca_px = m_whole_frame ? 2.0 * m_eye_px : layerPixels(fs.plan);
    work(m_costs.uca.at(uca_px, 0.0) + m_costs.frame_overhead_ms);
    rf.uca_end_ms = m_hs;
    rf.mtp_ms = rf.uca_end_ms - rf.pose_ms;
    // 7. Scan-out at the next free vsync slot. The runtime queues the image for its slot (two
    // images: the headset sleeps only while the previous frame still holds the other one,
    // VsyncPacer::queueForScanout); with wait_for_vsync it blocks until the slot.
    // Slots by index: a slot recomputed from a time is not bit-equal to the one stored.
    int64_t slot_k = static_cast<int64_t>(std::ceil(rf.uca_end_ms / m_period_ms - 1e-9));
    if (slot_k <= m_last_slot)
        slot_k = m_last_slot + 1;
    m_last_slot = slot_k;
    const double slot = double(slot_k) * m_period_ms;
    rf.display_ms = slot;
    m_hs = m_config.wait_for_vsync ? slot : std::max(m_hs, slot - m_period_ms);
    rf.headset_busy_ms = i > 0 ? m_busy : 0.0;
    m_busy = 0.0;
    if (m_config.record_scanout)
        work(m_costs.scanout_record_ms);
    rf.served = fs.served;
}

// 8. The policy learns what the frame measured.
void PassReplay::learn(int64_t i) {
    const RuntimeFrame& rf = m_result.frames[static_cast<size_t>(i)];
    const FrameState& fs = m_state[static_cast<size_t>(i)];
    const WorkloadFrame& wf = m_trace.frames[static_cast<size_t>(i)];
    FrameMeasurement m;
    m.index = wf.index;
    m.e1_deg = fs.plan.e1_deg;
    setHeadsetTimes(m, static_cast<int64_t>(m_depth), rf.headset_busy_ms, rf.t_local_ms);
    m.t_remote_ms = rf.requested ? rf.t_remote_ms : 0.0;
    if (isStartUpFrame(i, static_cast<int64_t>(m_depth), rf.requested || rf.withheld,
                       m_first_composed)) {
        m.t_local_ms = 0.0;
        m.t_render_ms = 0.0;
        m.t_remote_ms = 0.0;
    }
    m.triangles_local = sumWithinDeg(wf.triangles_per_ring, m_header.ring_deg, fs.plan.e1_deg);
    m.pixels_local = sumWithinDeg(wf.pixels_per_ring, m_header.ring_deg, fs.plan.e1_deg);
    m.middle_bytes = fs.middle_bytes > 0 && fs.received_bytes > 0 ? fs.middle_bytes : 0;
    m.outer_bytes = fs.outer_bytes > 0 && fs.received_bytes > 0 ? fs.outer_bytes : 0;
    m.middle_pixels = 2.0 * double(fs.plan.middle_pixels);
    m.outer_pixels = 2.0 * double(fs.plan.outer_pixels);
    m.s1 = fs.plan.s1;
    m.s2 = fs.plan.s2;
    m.throughput_bps = m_link_estimate.throughputBps();
    m.new_canvas_streams = fs.received_bytes > 0 ? fs.new_canvases : 0;
    m.periphery_late = rf.requested && fs.expected > 0 && fs.decoded < fs.expected &&
                       i >= static_cast<int64_t>(m_depth);
    m.periphery_withheld = fs.withheld;
    if (rf.requested && fs.expected > 0 && fs.decoded == fs.expected) {
        m.server_ms = fs.server_ms;
        m.request_ms = rf.request_ms;
        m.arrival_ms = fs.last_rx_ms;
    }
    m_policy->observe(m);
    m_state[static_cast<size_t>(i)].observed_late = m.periphery_late;
}

// Steps 4–8.
void PassReplay::finish(int64_t i) {
    renderFovea(i);
    const FrameState& fs = m_state[static_cast<size_t>(i)];
    const bool have_current = !fs.withheld && (fs.expected == 0 || waitForStreams(i));
    composeAndScanOut(i, have_current);
    if (m_first_composed < 0 && fs.expected > 0 && have_current)
        m_first_composed = i;
    if (m_policy && !m_local_only && !m_whole_frame)
        learn(i);
}

RuntimeRunResult summarizePass(RuntimeRunResult result, const RuntimeSimConfig& config,
                               int served_frames, double server_busy_total);

RuntimeRunResult PassReplay::run() {
    std::deque<int64_t> ahead;
    int64_t next = 0;
    for (int64_t i = 0; i < m_n_frames; ++i) {
        while (ahead.size() < m_depth && next < m_n_frames) {
            prepare(next);
            ahead.push_back(next++);
        }
        finish(ahead.front());
        ahead.pop_front();
    }
    // A frame the server rendered after the headset had shown it (reused) was still served.
    for (int64_t i = 0; i < m_n_frames; ++i) {
        RuntimeFrame& rf = m_result.frames[static_cast<size_t>(i)];
        const FrameState& fs = m_state[static_cast<size_t>(i)];
        rf.served = fs.served;
        rf.server_render_ms = fs.server_render_ms;
        rf.server_encode_ms = fs.server_encode_ms;
        rf.key_frames = fs.key_frames;
    }
    return summarizePass(std::move(m_result), m_config, m_served_frames, m_server_busy_total);
}

RuntimeRunResult summarizePass(RuntimeRunResult result, const RuntimeSimConfig& config,
                               int served_frames, double server_busy_total) {
    const int requests_dropped = result.summary.requests_dropped;
    const int requests_withheld = result.summary.requests_withheld;
    result.summary = summarizeRuntimeFrames(result.frames, config);
    result.summary.requests_dropped = requests_dropped;
    result.summary.requests_withheld = requests_withheld;
    if (served_frames > 0)
        result.summary.server_busy_ms_mean = server_busy_total / served_frames;
    return result;
}

RuntimeRunResult simulatePass(const WorkloadTrace& trace, const RuntimeSimConfig& config,
                              Link& link, const CoRunLog* previous, CoRunLog* log) {
    link.restart();  // each pass is the session again, from the trace's start
    return PassReplay(trace, config, link, previous, log).run();
}

}  // namespace

RuntimeRunResult simulateRuntime(const WorkloadTrace& trace, const RuntimeSimConfig& config,
                                 Link& link) {
    if (!(config.costs.headsetCoRun() > 1.0) && !(config.costs.serverCoRun() > 1.0))
        return simulatePass(trace, config, link, nullptr, nullptr);
    CoRunLog previous;
    RuntimeRunResult result = simulatePass(trace, config, link, nullptr, &previous);
    for (int pass = 0; pass < kCoRunMaxPasses; ++pass) {
        CoRunLog next;
        RuntimeRunResult again = simulatePass(trace, config, link, &previous, &next);
        double moved = 0.0;
        for (size_t k = 0; k < again.frames.size() && k < result.frames.size(); ++k)
            moved = std::max(moved,
                             std::fabs(again.frames[k].uca_end_ms - result.frames[k].uca_end_ms));
        result = std::move(again);
        previous = std::move(next);
        if (moved <= kCoRunSettledMs)
            break;
    }
    return result;
}

}  // namespace qvr
