// The headset's frame loop (paper Fig. 4): decide e1 → request periphery → render fovea →
// decode streams as they arrive → UCA with the newest pose → scan-out at the next vsync.
#include "qvr/runtime/headset_client.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <optional>

#include <fmt/format.h>

#include "qvr/codec/frame_header.h"
#include "qvr/compose/uca.h"
#include "qvr/controller/aimd.h"
#include "qvr/controller/liwc.h"
#include "qvr/controller/policy.h"
#include "qvr/core/request_window.h"
#include "qvr/core/silence.h"
#include "qvr/render/camera.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/cpu_share.h"
#include "qvr/runtime/workload_probe.h"

namespace qvr::runtime {

size_t pendingFramesToDrop(std::span<const size_t> bytes, size_t max_frames, size_t max_bytes) {
    size_t total = 0;
    for (size_t b : bytes)
        total += b;
    size_t drop = 0;
    while (bytes.size() - drop > 1 && (bytes.size() - drop > max_frames || total > max_bytes)) {
        total -= bytes[drop];
        ++drop;
    }
    return drop;
}

LayerPlan wholeFramePlan(const LayerPlanner& planner, const Gaze& gaze) {
    // Start from the all-local plan for its bookkeeping, then move the full frame to the
    // middle slot at scale 1: the server renders and streams it, the headset only warps it.
    LayerPlan p = planner.plan(gaze, 180.0);
    const PixelRect full = planner.geometry().fullRect();
    p.e1_deg = 0.0;
    p.e2_deg = p.cover_deg;
    p.s1 = 1.0;
    p.s2 = 1.0;
    for (EyeLayers& e : p.eyes) {
        e.fovea = LayerRect{};
        e.outer = LayerRect{};
        e.middle = LayerRect{full, 1.0, full.width(), full.height()};
    }
    p.fovea_pixels = 0;
    p.middle_pixels = full.area();
    p.outer_pixels = 0;
    p.fovea_fraction = 0.0;
    return p;
}

namespace {

// One frame waiting for its remote layers.
struct PendingFrame {
    int64_t frame = 0;
    size_t telemetry = 0;  // the frame's index in the run (Headset::tel)
    std::shared_ptr<LayerFrame> layers;
    uint8_t expected = 0;  // stream mask
    uint8_t decoded = 0;
    uint8_t failed = 0;
    int64_t request_ns = 0;
    // When the server could start on this frame: its request, or the moment the previous frame's
    // last stream arrived if that was later (the server renders one frame at a time, so with
    // frames in flight a request waits in its queue). T_remote is measured from here.
    int64_t service_start_ns = 0;
    int64_t last_rx_ns = 0;  // the newest packet of any of its streams
    std::array<double, net::kMaxStreams> bytes{};
    int new_canvas_streams = 0;  // decoded streams whose encoder opened a new canvas
    bool observed_late = false;  // the policy learnt the frame before its periphery came
    double server_ms = 0.0;      // the server's time on it, as its streams' headers say
    bool complete() const { return expected != 0 && (decoded & expected) == expected; }
    bool broken() const { return (failed & expected) != 0; }
};

uint8_t expectedStreams(const LayerPlan& plan) {
    uint8_t mask = 0;
    for (int eye = 0; eye < 2; ++eye) {
        if (!plan.eyes[static_cast<size_t>(eye)].middle.empty())
            mask |= static_cast<uint8_t>(1u << net::streamId(eye, net::Layer::kMiddle));
        if (!plan.eyes[static_cast<size_t>(eye)].outer.empty())
            mask |= static_cast<uint8_t>(1u << net::streamId(eye, net::Layer::kOuter));
    }
    return mask;
}

ImageRgba8& layerSlot(LayerFrame& f, uint8_t stream_id) {
    EyeLayerImages& e = f.eyes[stream_id / 2];
    return (stream_id % 2) == 0 ? e.middle : e.outer;
}

const LayerRect& layerRectOf(const LayerPlan& plan, uint8_t stream_id) {
    const EyeLayers& e = plan.eyes[stream_id / 2];
    return (stream_id % 2) == 0 ? e.middle : e.outer;
}

class Headset {
public:
    Headset(const HeadsetConfig& config, std::shared_ptr<const Scene> scene,
            std::shared_ptr<const TriangleBvh> bvh, const HeadsetTraces& traces)
        : m_config(config),
          m_clock(config.clock ? *config.clock : SteadyClock::instance()),
          m_pacer(m_clock, config.profile.refresh_hz),
          m_scene(std::move(scene)),
          m_traces(traces),
          m_planner(config.profile),
          m_probe(config.profile, std::move(bvh)),
          m_compositor(config.profile, composeOptions()),
          m_summary(designLabel(config.design, config.fixed_e1_deg), config.warmup_frames) {}

    static LiwcConfig liwcConfig(bool reactive, size_t depth) {
        LiwcConfig c;
        // A real server takes time to render and encode, less the larger the fovea; Eq. 2
        // alone would not see it. With frames in flight the display's period is the slowest
        // stage's, which is what LIWC minimises here (docs/LIWC.md).
        c.learn_remote_base = true;
        c.frame_period_objective = true;
        c.frames_in_flight = static_cast<int>(depth);
        c.reactive = reactive;
        return c;
    }

    // Frames prepared ahead of the one being finished. Without a server there is nothing to
    // overlap: one core renders and composes in turn.
    size_t pipelineDepth() const {
        return usesServer(m_config.design)
                   ? static_cast<size_t>(std::clamp(m_config.pipeline_depth, 1, 4))
                   : 1;
    }

    static ComposeOptions composeOptions() {
        ComposeOptions o;
        o.threads = 1;  // the headset has one core
        return o;
    }

    Status setUp() {
        if (m_traces.motion.samples.empty())
            return makeError("headset: the head-motion trace is empty");
        if (m_traces.gaze.samples.empty())
            return makeError("headset: the gaze trace is empty");
        auto r = m_config.renderer();
        if (!r)
            return makeError("headset: " + r.error());
        m_renderer = std::move(*r);
        if (auto st = m_renderer->upload(*m_scene); !st)
            return makeError("headset: " + st.error());
        if (m_config.cluster_ring_counts && (m_config.design == Design::Qvr ||
                                             m_config.design == Design::Sw || m_config.workload)) {
            // LIWC's rings from the draw clusters (what the fovea submits), not the BVH.
            auto clusters = std::make_shared<DrawList>(buildDrawList(*m_scene));
            if (m_config.lod_error_px > 0.0f)
                buildLods(*clusters, *m_scene);
            m_probe.useClusters(std::move(clusters), m_config.lod_error_px);
        }
        switch (m_config.design) {
            case Design::Qvr: {
                auto liwc = std::make_unique<LiwcPolicy>(m_probe.header(),
                                                         liwcConfig(false, pipelineDepth()));
                m_liwc = liwc.get();
                m_liwc_any = m_liwc;
                m_policy = std::move(liwc);
                break;
            }
            case Design::Sw: {
                // The same model as qvr's, fed as software would be (docs/RUNTIME.md).
                auto sw = std::make_unique<LiwcPolicy>(m_probe.header(),
                                                       liwcConfig(true, pipelineDepth()));
                m_liwc_any = sw.get();
                m_policy = std::move(sw);
                break;
            }
            case Design::Ffr:
            case Design::Fixed:
                m_policy = std::make_unique<FixedPolicy>(m_config.fixed_e1_deg);
                break;
            case Design::Aimd:
                m_policy = makeAimdPolicy(m_probe.header());
                break;
            default:
                break;
        }
        if (m_config.workload)
            m_config.workload->writeHeader(m_probe.header());
        if (usesServer(m_config.design)) {
            net::ClientOptions o;
            o.key = m_config.key;
            o.connect_timeout_ms = m_config.connect_timeout_ms;
            o.settings = net::makeSessionSettings(
                m_config.codec.backend, m_config.profile.name, m_config.profile.width_px,
                m_config.profile.height_px, m_config.profile.refresh_hz);
            m_client = std::make_unique<net::Client>(o);
        }
        return {};
    }

    HeadsetResult run() {
        HeadsetResult result;
        m_origin_ns = m_clock.nowNs();
        result.origin_ns = m_origin_ns;
        m_pacer.reset();
        // Read as the frames start: a headset joins its share group after it is set up.
        if (m_liwc_any)
            m_liwc_any->setHeadsetShare(cpuQuotaShare());
        if (m_client)
            tryConnect(true);
        // Frames are prepared (pose, decision, request) up to pipeline_depth ahead of the one
        // being finished (fovea, wait, UCA, scan-out).
        const size_t depth = pipelineDepth();
        m_depth = depth;
        std::deque<Prepared> ahead;
        int64_t next = 0;
        // A server that refused our version, codec or profile will not change its mind: stop.
        for (int64_t i = 0; i < m_config.frames && m_refusal.empty(); ++i) {
            while (ahead.size() < depth && next < m_config.frames && !stopRequested())
                ahead.push_back(prepare(next++));
            if (ahead.empty())
                break;  // stopped: every started frame was finished
            finish(ahead.front());
            ahead.pop_front();
            retireOldFrames(m_config.keep_frames);
        }
        // Streams still in flight belong to frames already shown: drain them so the server's
        // acks complete, then leave.
        if (m_client) {
            pumpNetwork(0);
            m_stats.net = m_client->stats();
            m_client->disconnect();
        }
        m_stats.core = currentCore();
        result.stats = m_stats;
        // The frames still held (all of them when keep_frames is 0) go to the summary and the
        // sink, and stay in the result.
        result.frames.reserve(m_frames.size());
        for (FrameTelemetry& t : m_frames) {
            retire(t);
            result.frames.push_back(std::move(t));
        }
        m_frames_base += m_frames.size();
        m_frames.clear();
        writeRetiredWorkload();
        result.summary = m_summary.finish();
        return result;
    }

private:
    bool stopRequested() const { return m_config.stop && m_config.stop->load(); }

    // A frame's telemetry by its index in the run.
    FrameTelemetry& tel(size_t ti) { return m_frames[ti - m_frames_base]; }
    // Frame `frame`'s telemetry while it is held (not yet retired into the summary), else null.
    // A frame's bytes are what arrived for it whenever they arrive (docs/RUNTIME.md step 5):
    // those of a frame already shown count too, until it is retired.
    FrameTelemetry* heldTelemetry(int64_t frame) {
        if (frame < 0 || static_cast<size_t>(frame) < m_frames_base)
            return nullptr;
        const size_t k = static_cast<size_t>(frame) - m_frames_base;
        if (k >= m_frames.size() || m_frames[k].frame != frame)
            return nullptr;
        return &m_frames[k];
    }

    // A frame whose telemetry is final: into the summary and the sink.
    void retire(const FrameTelemetry& t) {
        m_summary.add(t);
        if (m_config.frame_sink)
            m_config.frame_sink(t);
    }

    // With keep_frames set, frames more than that behind the newest (and never fewer than
    // kMinFramesHeld, past any frame whose late streams could still be counted) leave memory:
    // into the summary and the sink. Memory then stays flat however long the session runs.
    void retireOldFrames(size_t keep) {
        if (keep == 0)
            return;
        const size_t held = std::max(keep, kMinFramesHeld);
        while (m_frames.size() > held) {
            retire(m_frames.front());
            m_frames.pop_front();
            ++m_frames_base;
        }
        writeRetiredWorkload();
        // A frame that old is long past its wait limit: its streams, if they ever come, only
        // feed the decoders' reference chains.
        for (auto it = m_pending.begin(); it != m_pending.end();)
            it = it->telemetry < m_frames_base ? m_pending.erase(it) : std::next(it);
    }
    // The recorded workload of the frames retired so far, in frame order.
    void writeRetiredWorkload() {
        while (!m_unwritten_workload.empty() &&
               m_unwritten_workload.front().index < static_cast<int64_t>(m_frames_base)) {
            m_config.workload->writeFrame(m_unwritten_workload.front());
            m_unwritten_workload.pop_front();
        }
    }
    int64_t rel(int64_t t_ns) const { return t_ns - m_origin_ns; }
    double frameTimeMs(int64_t i) const { return contentTimeMs(i, m_config.profile.refresh_hz); }

    void tryConnect(bool force) {
        const int64_t now_ns = m_clock.nowNs();
        if (!force &&
            now_ns - m_last_connect_try_ns < int64_t(m_config.reconnect_interval_ms) * 1'000'000)
            return;
        m_last_connect_try_ns = now_ns;
        if (auto st = m_client->connect(m_config.host, m_config.port); st) {
            ++m_stats.connects;
            m_silence.restart(double(m_clock.nowNs()) * 1e-6);  // a whole limit to start
            // A new session: new encoders on the server, so new decoders here.
            for (auto& d : m_decoders)
                d.reset();
            m_pending.clear();
        } else {
            ++m_stats.connect_failures;
            // A server that cannot prove the key will not learn it in 250 ms: back off.
            const uint64_t proof_failures = m_client->stats().server_proof_failures;
            if (proof_failures > m_proof_failures_seen)
                m_last_connect_try_ns = now_ns + int64_t(kKeyMismatchBackoffMs) * 1'000'000;
            m_proof_failures_seen = proof_failures;
            if (m_client->stats().incompatible_refusals > 0 ||
                m_client->stats().capacity_refusals > 0)
                m_refusal = st.error();
        }
    }

    VideoDecoder* decoder(uint8_t stream_id) {
        auto& d = m_decoders[stream_id];
        if (!d) {
            auto made = makeVideoDecoder(m_config.codec);
            if (!made)
                return nullptr;
            d = std::move(*made);
        }
        return d.get();
    }

    // Holds the pending list to its bounds (kMaxPendingFrames, kMaxPendingImageBytes) at each
    // request. With 8 entries, as before, a server at 661 ms a frame (a slow validation run, 40
    // frames) finished only frames whose entries were already gone and showed nothing.
    void trimPending() {
        std::vector<size_t> bytes;
        bytes.reserve(m_pending.size());
        for (const PendingFrame& p : m_pending)
            bytes.push_back(imageBytes(*p.layers));
        for (size_t n = pendingFramesToDrop(bytes, kMaxPendingFrames, kMaxPendingImageBytes); n > 0;
             --n)
            m_pending.pop_front();
    }
    static size_t imageBytes(const LayerFrame& f) {
        size_t n = 0;
        for (const EyeLayerImages& e : f.eyes)
            n += e.fovea.sizeBytes() + e.middle.sizeBytes() + e.outer.sizeBytes();
        return n;
    }

    // The requests still outstanding (qvr/core/request_window.h).
    size_t outstandingRequests() {
        const int64_t now_ns = m_clock.nowNs();
        const uint64_t packets = m_client->stats().assembler.packets_accepted;
        if (packets != m_packets_seen) {
            m_packets_seen = packets;
            m_last_packet_ns = now_ns;
        }
        const double last_packet_ms = m_last_packet_ns > 0 ? double(m_last_packet_ns) * 1e-6 : -1.0;
        size_t n = 0;
        for (const PendingFrame& p : m_pending)
            n += !p.complete() && !p.broken() && p.frame > m_newest_complete_frame &&
                 RequestWindow::holds(double(p.request_ns) * 1e-6, double(now_ns) * 1e-6,
                                      last_packet_ms, m_config.remote_timeout_ms);
        return n;
    }

    PendingFrame* pendingFor(int64_t frame) {
        for (PendingFrame& p : m_pending)
            if (p.frame == frame)
                return &p;
        return nullptr;
    }

    void onStream(net::CompletedStream& cs) {
        ++m_stats.streams_received;
        m_silence.onStream(double(m_clock.nowNs()) * 1e-6);
        if (cs.stream_id >= net::kMaxStreams)
            return;
        PendingFrame* p = pendingFor(cs.frame_id);
        if (p) {
            FrameTelemetry& t = tel(p->telemetry);
            t.stream_rx_ns[cs.stream_id] = rel(cs.last_rx_ns);
            p->last_rx_ns = std::max(p->last_rx_ns, cs.last_rx_ns);
            t.bytes += static_cast<int64_t>(cs.bytes.size());
            p->bytes[cs.stream_id] += static_cast<double>(cs.bytes.size());
            // A peer's number: bounded (10 s) before a fit sees it.
            p->server_ms =
                std::max(p->server_ms, std::min(10'000.0, frameServerUs(cs.bytes) * 1e-3));
        } else if (FrameTelemetry* shown = heldTelemetry(cs.frame_id)) {
            // Already shown (late, reused): its bytes crossed the link all the same.
            shown->bytes += static_cast<int64_t>(cs.bytes.size());
        }
        // Every frame goes through its stream's decoder, shown or not: later frames refer to it.
        VideoDecoder* dec = decoder(cs.stream_id);
        if (!dec) {
            ++m_stats.decode_failures;
            return;
        }
        const int64_t decode_start_ns = m_clock.nowNs();
        auto image = dec->decode(cs.bytes);
        if (p)
            tel(p->telemetry).decode_ms += double(m_clock.nowNs() - decode_start_ns) * 1e-6;
        if (!image) {
            ++m_stats.decode_failures;
            if (p)
                p->failed |= static_cast<uint8_t>(1u << cs.stream_id);
            if (dec->needsKeyframe() && m_client->connected()) {
                const int64_t now_ns = m_clock.nowNs();
                if (now_ns - m_last_key_request_ns[cs.stream_id] > 100'000'000) {
                    m_last_key_request_ns[cs.stream_id] = now_ns;
                    if (m_client->requestKeyFrame(static_cast<uint8_t>(1u << cs.stream_id),
                                                  cs.frame_id, net::KeyFrameReason::kDecoderError))
                        ++m_stats.key_frame_requests;
                }
            }
            return;
        }
        ++m_stats.streams_decoded;
        if (!p) {
            ++m_stats.streams_discarded;
            return;
        }
        const LayerRect& r = layerRectOf(p->layers->plan, cs.stream_id);
        if (image->width() != r.width_px || image->height() != r.height_px) {
            ++m_stats.decode_failures;
            p->failed |= static_cast<uint8_t>(1u << cs.stream_id);
            return;
        }
        layerSlot(*p->layers, cs.stream_id) = std::move(*image);
        p->decoded |= static_cast<uint8_t>(1u << cs.stream_id);
        if (frameFlags(cs.bytes) & FrameHeader::kFlagNewCanvas)
            ++p->new_canvas_streams;
        FrameTelemetry& t = tel(p->telemetry);
        t.stream_decoded_ns[cs.stream_id] = rel(m_clock.nowNs());
        if (p->complete()) {
            if (p->observed_late)
                m_policy->observeLateArrival({p->frame, p->bytes[0] + p->bytes[2],
                                              p->bytes[1] + p->bytes[3], p->new_canvas_streams});
            t.remote_done_ns = rel(m_clock.nowNs());
            t.server_ms = p->server_ms;
            m_last_complete_rx_ns = std::max(m_last_complete_rx_ns, p->last_rx_ns);
            m_newest_complete_frame = std::max(m_newest_complete_frame, p->frame);
            for (PendingFrame& later : m_pending)
                if (later.frame > p->frame)
                    later.service_start_ns = std::max(later.service_start_ns, p->last_rx_ns);
        }
    }

    // Takes what the transport has, waiting up to wait_ms for the first stream.
    void pumpNetwork(int wait_ms) {
        if (!m_client)
            return;
        int timeout_ms = wait_ms;
        for (;;) {
            const int64_t block_start_ns = timeout_ms > 0 ? m_clock.nowNs() : 0;
            auto next = m_client->nextStream(timeout_ms);
            if (timeout_ms > 0)
                m_idle_ns += m_clock.nowNs() - block_start_ns;
            if (!next) {
                if (m_was_connected) {
                    ++m_stats.disconnects;
                    m_was_connected = false;
                }
                break;
            }
            if (!next->has_value())
                break;
            onStream(**next);
            timeout_ms = 0;
        }
        for (const net::LostStream& l : m_client->takeLost()) {
            ++m_stats.streams_lost;
            if (PendingFrame* p = pendingFor(l.frame_id)) {
                p->failed |= static_cast<uint8_t>(1u << l.stream_id);
                tel(p->telemetry).bytes += l.bytes_received;
                p->bytes[l.stream_id] += l.bytes_received;
            } else if (FrameTelemetry* shown = heldTelemetry(l.frame_id)) {
                shown->bytes += l.bytes_received;
            }
        }
    }

    // A frame between its request and its scan-out.
    struct Prepared {
        int64_t frame = 0;
        size_t telemetry = 0;
        int64_t pose_ns = 0;
        double content_ms = 0.0;
        Pose head;
        Gaze gaze;
        LayerPlan plan;
        std::optional<WorkloadFrame> wf;
        bool decided = false;
        uint8_t expected = 0;
        bool withheld = false;  // its periphery was not asked for: the request window was full
        std::shared_ptr<LayerFrame> layers;
    };

    // A frame's layer plan and how it was chosen.
    struct Choice {
        LayerPlan plan;
        bool decided = false;   // the policy chose e1
        bool fallback = false;  // no server: everything local
        double t_local_pred_ms = 0.0;
        double t_remote_pred_ms = 0.0;
    };

    // 2. Decision: e1 before rendering.
    Choice decide(int64_t i, double content_ms, const Pose& head, const Gaze& gaze, bool connected,
                  const std::optional<WorkloadFrame>& wf) {
        Choice c;
        switch (m_config.design) {
            case Design::Local:
                c.plan = m_planner.plan(gaze, 180.0);
                break;
            case Design::Remote:
                if (connected) {
                    c.plan = wholeFramePlan(m_planner, gaze);
                } else {
                    c.plan = m_planner.plan(gaze, 180.0);
                    c.fallback = true;
                }
                break;
            default:
                if (connected) {
                    // Policies other than LIWC read only the pose and gaze (policy.h).
                    WorkloadFrame light;
                    if (!wf) {
                        light.index = i;
                        light.time_ms = content_ms;
                        light.head = head;
                        light.gaze = gaze;
                    }
                    if (m_liwc)
                        m_liwc->setLinkEstimate(m_client->throughputBps());
                    const Decision d = m_policy->decide(wf ? *wf : light);
                    m_last_e1_deg = d.e1_deg;
                    c.t_local_pred_ms = d.t_local_pred_ms;
                    c.t_remote_pred_ms = d.t_remote_pred_ms;
                    c.plan = m_planner.plan(gaze, d.e1_deg);
                    c.decided = true;
                } else {
                    c.plan = m_planner.plan(gaze, 180.0);
                    c.fallback = true;
                }
                break;
        }
        return c;
    }

    // Steps 1–3: pose sample, decision, request.
    Prepared prepare(int64_t i) {
        if (m_config.before_frame)
            m_config.before_frame(i);
        m_frames.emplace_back();
        const size_t ti = m_frames_base + m_frames.size() - 1;
        FrameTelemetry& t0 = tel(ti);
        t0.frame = i;

        // 1. Pose and gaze sample: the start of motion-to-photon.
        const int64_t pose_ns = m_clock.nowNs();
        t0.pose_ns = rel(pose_ns);
        const double content_ms = frameTimeMs(i);
        const Pose head = poseAt(m_traces.motion, content_ms);
        const Gaze gaze = gazeAt(m_traces.gaze, content_ms);

        // Keep the transport drained and the session alive.
        if (m_client) {
            pumpNetwork(0);
            if (!m_client->connected())
                tryConnect(false);
            m_was_connected = m_client->connected();
        }
        const bool connected = m_client && m_client->connected();
        tel(ti).connected = connected;

        // 2. Decision: e1 before rendering.
        const bool needs_workload =
            m_config.design == Design::Qvr || m_config.design == Design::Sw || m_config.workload;
        std::optional<WorkloadFrame> wf;
        double probe_ms = 0.0;
        if (needs_workload) {
            const int64_t probe_start_ns = m_clock.nowNs();
            // With the BVH, rings past the last e1 + 6° are lumped into the last counted one
            // (totals stay exact); the clusters' count costs the same for every ring.
            wf = m_config.cluster_ring_counts
                     ? m_probe.frame(i, content_ms, head, gaze)
                     : m_probe.frame(i, content_ms, head, gaze, m_last_e1_deg + 6.0);
            probe_ms = double(m_clock.nowNs() - probe_start_ns) * 1e-6;
        }
        const Choice choice = decide(i, content_ms, head, gaze, connected, wf);
        const LayerPlan& plan = choice.plan;
        const bool decided = choice.decided;
        const bool fallback = choice.fallback;
        const double t_local_pred_ms = choice.t_local_pred_ms;
        const double t_remote_pred_ms = choice.t_remote_pred_ms;
        FrameTelemetry* t = &tel(ti);
        t->decision_ns = rel(m_clock.nowNs());
        t->fallback_local = fallback;
        t->probe_ms = probe_ms;
        t->t_local_pred_ms = t_local_pred_ms;
        t->t_remote_pred_ms = t_remote_pred_ms;
        t->e1_deg = m_config.design == Design::Remote && !fallback ? 0.0
                    : m_config.design == Design::Local || fallback ? plan.cover_deg
                                                                   : plan.e1_deg;
        t->e2_deg = plan.e2_deg;
        if (wf)
            t->fovea_triangles =
                sumWithinDeg(wf->triangles_per_ring, m_probe.header().ring_deg, plan.e1_deg);

        auto layers = std::make_shared<LayerFrame>();
        layers->frame_index = static_cast<uint64_t>(i);
        layers->plan = plan;
        layers->render_pose = head;

        // 3. Request the periphery first, so the server works while the fovea renders; not while
        // the window of outstanding requests is full (qvr/core/request_window.h).
        uint8_t expected = connected ? expectedStreams(plan) : 0;
        const bool withheld =
            expected != 0 && outstandingRequests() >= RequestWindow::window(m_depth);
        if (withheld) {
            expected = 0;
            ++m_stats.requests_withheld;
            t->request_withheld = true;
        }
        if (expected != 0) {
            const net::FrameRequest req = net::makeFrameRequest(
                static_cast<uint32_t>(i), static_cast<uint64_t>(pose_ns), head, plan);
            if (m_client->sendFrameRequest(req)) {
                PendingFrame p;
                p.frame = i;
                p.telemetry = ti;
                p.layers = layers;
                p.expected = expected;
                p.request_ns = m_clock.nowNs();
                p.service_start_ns = std::max(p.request_ns, m_last_complete_rx_ns);
                t->request_ns = rel(p.request_ns);
                t->remote_requested = true;
                m_pending.push_back(p);
                trimPending();
            }
        }

        Prepared prep;
        prep.frame = i;
        prep.telemetry = ti;
        prep.pose_ns = pose_ns;
        prep.content_ms = content_ms;
        prep.head = head;
        prep.gaze = gaze;
        prep.plan = plan;
        prep.wf = std::move(wf);
        prep.decided = decided;
        prep.expected = expected;
        prep.withheld = withheld;
        prep.layers = std::move(layers);
        return prep;
    }

    // Steps 4–7: fovea, remote layers, UCA, scan-out, what the policy learns.
    void finish(Prepared& prep) {
        const int64_t local_end_ns = renderFovea(prep);
        const bool have_current =
            !prep.withheld && (prep.expected == 0 || waitForRemote(prep, local_end_ns));
        composeAndScanOut(prep, have_current);
        if (prep.decided)
            learn(prep, have_current);
        // Frames already shown keep their slot only until their streams are decoded.
        while (!m_pending.empty() &&
               (m_pending.front().frame <= m_last_shown && m_pending.front().frame < prep.frame))
            m_pending.pop_front();
    }

    // 4. The fovea (or the whole frame) locally; returns when it ended.
    int64_t renderFovea(Prepared& prep) {
        const LayerPlan& plan = prep.plan;
        const int64_t local_start_ns = m_clock.nowNs();
        tel(prep.telemetry).local_start_ns = rel(local_start_ns);
        double fragments = 0.0, pixels = 0.0;
        bool counted = true;
        for (int eye = 0; eye < 2; ++eye) {
            const LayerRect& fovea = plan.eyes[static_cast<size_t>(eye)].fovea;
            if (fovea.empty())
                continue;
            auto rs =
                renderLayer(*m_renderer, m_config.profile, plan, prep.head, static_cast<Eye>(eye),
                            LayerKind::kFovea, prep.layers->eyes[static_cast<size_t>(eye)].fovea);
            if (!rs) {
                ++m_stats.render_failures;
                counted = false;
            } else {
                fragments += double(rs->fragment_invocations);
                pixels += double(fovea.pixels());
            }
        }
        const int64_t local_end_ns = m_clock.nowNs();
        FrameTelemetry* t = &tel(prep.telemetry);
        t->local_end_ns = rel(local_end_ns);
        t->fovea_fragments = fragments;
        t->t_local_ms = double(local_end_ns - local_start_ns) * 1e-6;
        recordWorkload(prep, counted && pixels > 0.0 ? fragments / pixels : -1.0);
        return local_end_ns;
    }

    // The frame's workload as LIWC counted it, with the fragments its fovea pass shaded per
    // fovea pixel (docs/WORKLOAD_FORMAT.md frag_px); written when the frame retires, so the
    // frames do not pay the JSON.
    void recordWorkload(Prepared& prep, double fragments_per_px) {
        if (!m_config.workload || !prep.wf)
            return;
        prep.wf->fovea_fragments_per_px = std::min(fragments_per_px, 1e3);
        m_unwritten_workload.push_back(*prep.wf);
    }

    // When to stop waiting for a frame's remote layers. The wait limit runs from when the server
    // could start on this frame: with frames in flight its request waits behind the previous
    // frame's. A server that has delivered no stream for a whole wait limit is stalled or its
    // link is dead: waiting the limit for every frame would drop the display to 1 / limit (4 Hz
    // at 250 ms, measured under a 2 s SIGSTOP of the server). Then wait one refresh and re-warp
    // the newest layers, until streams come again. A server whose streams are spaced wider than
    // half the limit is given twice its spacing before it is called silent (qvr/core/silence.h).
    int64_t remoteDeadlineNs(const Prepared& prep, int64_t local_end_ns) {
        const PendingFrame* started = pendingFor(prep.frame);
        const int64_t wait_from_ns =
            std::max({local_end_ns, prep.pose_ns, started ? started->service_start_ns : 0});
        const int64_t limit_ns = static_cast<int64_t>(m_config.remote_timeout_ms * 1e6);
        const bool silent =
            m_silence.silent(double(local_end_ns) * 1e-6, m_config.remote_timeout_ms);
        if (!silent)
            return wait_from_ns + limit_ns;
        ++m_stats.silent_server_frames;
        return std::max(local_end_ns, prep.pose_ns) +
               static_cast<int64_t>(1e9 / m_config.profile.refresh_hz);
    }

    // 5. Waits for this frame's remote layers, decoding each as it arrives; whether they all
    // came.
    bool waitForRemote(const Prepared& prep, int64_t local_end_ns) {
        const int64_t i = prep.frame;
        const int64_t deadline_ns = remoteDeadlineNs(prep, local_end_ns);
        for (;;) {
            PendingFrame* p = pendingFor(i);
            if (!p || p->complete() || p->broken())
                break;
            const int64_t now_ns = m_clock.nowNs();
            if (now_ns >= deadline_ns || !m_client->connected())
                break;
            const int wait_ms =
                static_cast<int>(std::clamp<int64_t>((deadline_ns - now_ns) / 1'000'000, 1, 5));
            pumpNetwork(wait_ms);
        }
        PendingFrame* p = pendingFor(i);
        FrameTelemetry* t = &tel(prep.telemetry);
        const bool have_current = p && p->complete();
        const int64_t now_ns = m_clock.nowNs();
        const int64_t decoded_ns = have_current ? m_origin_ns + t->remote_done_ns : now_ns;
        // The last packet's arrival, not its decode: decoding waits while the headset renders its
        // own fovea on the same core, which is headset time, not the server's.
        const int64_t rx_ns = have_current && p->last_rx_ns > 0 ? p->last_rx_ns : now_ns;
        const int64_t start_ns = p ? p->service_start_ns : m_origin_ns + t->request_ns;
        t->t_remote_ms = double(rx_ns - std::min(start_ns, rx_ns)) * 1e-6;
        t->t_remote_decoded_ms = double(decoded_ns - std::min(start_ns, decoded_ns)) * 1e-6;
        if (!have_current)
            ++m_stats.late_frames;
        return have_current;
    }

    // The layers to compose when this frame's did not all come: a frame older than this one
    // whose layers completed after its own display is newer than what the compositor holds, so
    // show it (still a reuse of older layers); null: re-warp what the compositor holds.
    std::shared_ptr<const LayerFrame> newerLateLayers(int64_t i) const {
        for (auto it = m_pending.rbegin(); it != m_pending.rend(); ++it) {
            if (it->frame < i && it->complete() &&
                static_cast<int64_t>(it->layers->frame_index) > m_last_shown)
                return it->layers;
        }
        return nullptr;
    }

    // 6. UCA with the newest pose, then scan-out at the next vsync.
    void composeAndScanOut(const Prepared& prep, bool have_current) {
        const int64_t uca_start_ns = m_clock.nowNs();
        const Pose display_pose =
            poseAt(m_traces.motion, prep.content_ms + double(uca_start_ns - prep.pose_ns) * 1e-6);
        const std::shared_ptr<const LayerFrame> arrived =
            have_current ? prep.layers : newerLateLayers(prep.frame);
        bool reused = !have_current;
        auto report = m_compositor.present(arrived, display_pose, m_display);
        if (!report) {
            ++m_stats.compose_failures;
            // Nothing to re-warp yet (the very first frame was late): show the local part.
            reused = true;
        }
        const int64_t uca_end_ns = m_clock.nowNs();
        FrameTelemetry* t = &tel(prep.telemetry);
        t->uca_start_ns = rel(uca_start_ns);
        t->uca_end_ns = rel(uca_end_ns);
        t->uca_ms = double(uca_end_ns - uca_start_ns) * 1e-6;
        t->mtp_ms = double(uca_end_ns - prep.pose_ns) * 1e-6;
        t->reused = reused || (report && report->reused);
        if (report) {
            t->shown_frame = static_cast<int64_t>(report->frame_index);
            t->warp_deg = report->warp_deg;
            m_last_shown = t->shown_frame;
            if (m_first_composed_frame < 0)
                m_first_composed_frame = prep.frame;
        }
        t->throughput_bps = m_client ? m_client->throughputBps() : 0.0;
        const int64_t vsync_wait_start_ns = m_clock.nowNs();
        const int64_t display_ns = m_config.wait_for_vsync ? m_pacer.waitForScanout(uca_end_ns)
                                                           : m_pacer.queueForScanout(uca_end_ns);
        m_idle_ns += std::max<int64_t>(0, m_clock.nowNs() - vsync_wait_start_ns);
        // Busy time since the previous frame finished: the headset's cost of one frame.
        const int64_t now_ns = m_clock.nowNs();
        if (m_last_finish_ns > 0)
            tel(prep.telemetry).headset_busy_ms =
                double(std::max<int64_t>(0, now_ns - m_last_finish_ns - m_idle_ns)) * 1e-6;
        m_last_finish_ns = now_ns;
        m_idle_ns = 0;
        t = &tel(prep.telemetry);
        t->display_ns = rel(display_ns);
        if (m_config.display && report) {
            const LayerFrame* shown = m_compositor.newestFrame();
            m_config.display->onScanout(*t, shown ? shown->plan : prep.plan, m_display);
        }
    }

    // 7. The policy learns what the frame measured.
    void learn(const Prepared& prep, bool have_current) {
        const int64_t i = prep.frame;
        const LayerPlan& plan = prep.plan;
        const FrameTelemetry* t = &tel(prep.telemetry);
        PendingFrame* p = pendingFor(i);
        FrameMeasurement m;
        m.index = i;
        m.e1_deg = plan.e1_deg;
        setHeadsetTimes(m, static_cast<int64_t>(m_depth), t->headset_busy_ms, t->t_local_ms);
        m.t_decode_ms = t->decode_ms;
        m.t_remote_ms = t->remote_requested ? t->t_remote_ms : 0.0;
        if (isStartUpFrame(i, static_cast<int64_t>(m_depth), t->remote_requested || prep.withheld,
                           m_first_composed_frame)) {
            m.t_local_ms = 0.0;
            m.t_render_ms = 0.0;
            m.t_decode_ms = 0.0;
            m.t_remote_ms = 0.0;
        }
        if (prep.wf) {
            m.triangles_local =
                sumWithinDeg(prep.wf->triangles_per_ring, m_probe.header().ring_deg, plan.e1_deg);
            m.pixels_local =
                sumWithinDeg(prep.wf->pixels_per_ring, m_probe.header().ring_deg, plan.e1_deg);
        }
        if (p) {
            m.middle_bytes = p->bytes[0] + p->bytes[2];
            m.outer_bytes = p->bytes[1] + p->bytes[3];
            m.new_canvas_streams = p->new_canvas_streams;
        }
        m.middle_pixels = 2.0 * double(plan.middle_pixels);
        m.outer_pixels = 2.0 * double(plan.outer_pixels);
        m.s1 = plan.s1;
        m.s2 = plan.s2;
        m.throughput_bps = t->throughput_bps;
        m.periphery_late =
            t->remote_requested && !have_current && i >= static_cast<int64_t>(m_depth);
        m.periphery_withheld = prep.withheld;
        if (p && have_current)
            m.server_ms = p->server_ms;
        if (p && have_current && p->last_rx_ns > 0) {
            m.request_ms = double(p->request_ns - m_origin_ns) * 1e-6;
            m.arrival_ms = double(p->last_rx_ns - m_origin_ns) * 1e-6;
        }
        m_policy->observe(m);
        if (p && m.periphery_late)
            p->observed_late = true;
        if (p && have_current)
            m_probe.observeBits(m.middle_bytes, m.middle_pixels, plan.s1, m.outer_bytes,
                                m.outer_pixels, plan.s2);
    }

    // No more pending frames than the telemetry holds: an older entry would be dropped with
    // its frame's telemetry anyway (retireOldFrames).
    static constexpr size_t kMinFramesHeld = 64;
    static_assert(kMaxPendingFrames <= kMinFramesHeld);
    static constexpr int kKeyMismatchBackoffMs = 2000;

    const HeadsetConfig& m_config;
    Clock& m_clock;
    VsyncPacer m_pacer;
    std::shared_ptr<const Scene> m_scene;
    const HeadsetTraces& m_traces;
    LayerPlanner m_planner;
    WorkloadProbe m_probe;
    Compositor m_compositor;
    std::unique_ptr<Renderer> m_renderer;
    std::unique_ptr<FoveaPolicy> m_policy;
    LiwcPolicy* m_liwc = nullptr;      // m_policy when it is qvr's LIWC
    LiwcPolicy* m_liwc_any = nullptr;  // m_policy when it is LIWC, qvr's or sw's
    double m_last_e1_deg = kFfrE1Deg;
    std::unique_ptr<net::Client> m_client;
    std::array<std::unique_ptr<VideoDecoder>, net::kMaxStreams> m_decoders;
    std::array<int64_t, net::kMaxStreams> m_last_key_request_ns{};
    std::deque<PendingFrame> m_pending;
    std::deque<FrameTelemetry> m_frames;  // the frames not yet retired, from m_frames_base
    size_t m_frames_base = 0;
    std::deque<WorkloadFrame> m_unwritten_workload;  // recorded, not yet retired (in order)
    RunSummarizer m_summary;
    std::array<ImageRgba8, 2> m_display;
    HeadsetStats m_stats;
    int64_t m_origin_ns = 0;
    int64_t m_last_connect_try_ns = 0;
    int64_t m_last_shown = -1;
    int64_t m_first_composed_frame = -1;  // the first frame UCA composed from layers
    int64_t m_last_complete_rx_ns = 0;
    int64_t m_newest_complete_frame = -1;  // the newest frame whose periphery all came
    uint64_t m_packets_seen = 0;           // media packets accepted, at the last look
    int64_t m_last_packet_ns = 0;          // when that count last grew (0: never)
    SilenceDetector m_silence;  // the newest streams from the server, or the session's start
    int64_t m_idle_ns = 0;      // waiting for the network or vsync since the last frame finished
    int64_t m_last_finish_ns = 0;
    size_t m_depth = 1;
    uint64_t m_proof_failures_seen = 0;
    std::string m_refusal;  // why the server refused our settings or for capacity; empty: not

public:
    const std::string& refusal() const { return m_refusal; }

private:
    bool m_was_connected = false;
};

}  // namespace

Expected<HeadsetResult> runHeadset(const HeadsetConfig& config, std::shared_ptr<const Scene> scene,
                                   std::shared_ptr<const TriangleBvh> bvh,
                                   const HeadsetTraces& traces) {
    if (!scene || !bvh)
        return makeError("headset: no scene");
    if (config.frames < 0)
        return makeError("headset: negative frame count");
    if (config.core >= 0) {
        if (auto st = pinCurrentThread(config.core); !st)
            std::fprintf(stderr, "qvr client: %s (running unpinned)\n", st.error().c_str());
    }
    auto headset = std::make_unique<Headset>(config, std::move(scene), std::move(bvh), traces);
    if (auto st = headset->setUp(); !st)
        return makeError(st.error());
    HeadsetResult result = headset->run();
    if (!headset->refusal().empty())
        return makeError(headset->refusal());
    return result;
}

}  // namespace qvr::runtime
