// The render server: a bounded request queue per headset, a pool of render workers that take
// ready headsets in turn and render, encode and send each periphery layer as soon as it is ready
// (paper Fig. 7's parallel streams), and admission by the server's cost per headset-frame.
#include "qvr/runtime/render_server.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include <sys/resource.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "qvr/codec/frame_header.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/render/periphery_pass.h"
#include "qvr/runtime/affinity.h"

namespace qvr::runtime {

namespace {

// The process's CPU time so far, every thread, user and system.
double processCpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    const auto ms = [](const timeval& t) {
        return double(t.tv_sec) * 1e3 + double(t.tv_usec) * 1e-3;
    };
    return ms(u.ru_utime) + ms(u.ru_stime);
}

}  // namespace

RendererFactory glRendererFactory(GlRendererOptions options) {
    return [options]() -> Expected<std::unique_ptr<Renderer>> {
        auto r = GlRenderer::create(options);
        if (!r)
            return makeError(r.error());
        return std::unique_ptr<Renderer>(std::move(*r));
    };
}

RendererFactory nullRendererFactory() {
    return []() -> Expected<std::unique_ptr<Renderer>> { return makeNullRenderer(); };
}

double sustainedFps(int headsets, int workers, double frame_cost_ms, double refresh_hz) {
    if (headsets <= 0 || frame_cost_ms <= 0.0)
        return refresh_hz;
    const double share = std::min(1.0, double(std::max(workers, 1)) / double(headsets));
    return std::min(refresh_hz, 1000.0 / frame_cost_ms * share);
}

std::string admissionRefusal(const AdmissionConfig& a, int admitted, int workers,
                             double frame_cost_ms, double refresh_hz) {
    if (a.min_fps <= 0.0)
        return {};
    const int headsets = admitted + 1;
    if (frame_cost_ms <= 0.0) {
        if (headsets <= std::max(workers, 1))
            return {};
        return fmt::format(
            "{} headsets on {} workers, and no cost per headset-frame known to hold {:g} fps "
            "(no calibration, fewer than {} frames served)",
            headsets, workers, a.min_fps, a.measure_frames);
    }
    const double fps = sustainedFps(headsets, workers, frame_cost_ms, refresh_hz);
    if (fps >= a.min_fps)
        return {};
    return fmt::format(
        "{} headsets would get {:.1f} fps each at {:.2f} ms a headset-frame on {} workers, below "
        "the floor of {:g} fps",
        headsets, fps, frame_cost_ms, workers, a.min_fps);
}

nlohmann::json serverPoolJson(const RenderServerStats& s) {
    nlohmann::json sessions = nlohmann::json::array();
    for (const SessionStats& x : s.sessions) {
        const auto mean = [&](double total) {
            return x.frames_rendered > 0 ? total / double(x.frames_rendered) : 0.0;
        };
        sessions.push_back(
            {{"client", x.client},
             {"connected", x.connected},
             {"connected_s", x.connected_s},
             {"frames_requested", x.frames_requested},
             {"frames_dropped", x.frames_dropped},
             {"frames_rendered", x.frames_rendered},
             {"frames_encoded", x.frames_encoded},
             {"frames_sent", x.frames_sent},
             {"fps_sent", x.connected_s > 0.0 ? double(x.frames_sent) / x.connected_s : 0.0},
             {"streams_sent", x.streams_sent},
             {"stream_send_failures", x.stream_send_failures},
             {"render_ms_mean", mean(x.render_ms_total)},
             {"encode_ms_mean", mean(x.encode_ms_total)},
             {"service_ms_mean", mean(x.service_ms_total)},
             {"queue_ms_mean", mean(x.queue_ms_total)}});
    }
    double service_ms = 0.0, frames = 0.0;
    for (const SessionStats& x : s.sessions) {
        service_ms += x.service_ms_total;
        frames += double(x.frames_rendered);
    }
    return {{"workers", s.workers},
            {"cpu_ms_per_frame", s.cpu_ms_per_frame},
            {"admission",
             {{"min_fps", s.min_fps},
              {"frame_cost_ms", s.frame_cost_ms},
              {"frame_cost_source", s.frame_cost_source},
              {"refused_capacity", s.net.refused_capacity}}},
            {"sessions", std::move(sessions)},
            {"share_periphery",
             sharePeripheryJson(s.share_periphery, frames > 0.0 ? service_ms / frames : 0.0)}};
}

namespace {

struct SessionState {
    struct Queued {
        net::FrameRequest request;
        int64_t queued_ns = 0;
    };
    // Guarded by Impl::mutex.
    std::deque<Queued> pending;
    bool in_service = false;  // a worker is serving one of its frames (and holds its encoders)
    int64_t admitted_ns = 0;
    int64_t ended_ns = 0;  // 0 while connected
    SessionStats stats;
    std::atomic<uint8_t> key_frame_mask{0};
    // Used only by the worker that has the session in service: the mutex hands them over.
    std::array<std::unique_ptr<VideoEncoder>, net::kMaxStreams> encoders;
};
using Queued = SessionState::Queued;
using Encoders = std::array<std::unique_ptr<VideoEncoder>, net::kMaxStreams>;

bool layerFits(const HmdProfile& profile, const LayerRect& l) {
    if (l.empty())
        return true;
    return l.rect.x0 >= 0 && l.rect.y0 >= 0 && l.rect.x1 <= profile.width_px &&
           l.rect.y1 <= profile.height_px && l.width_px <= profile.width_px &&
           l.height_px <= profile.height_px;
}

bool planFits(const HmdProfile& profile, const LayerPlan& plan) {
    for (const EyeLayers& e : plan.eyes)
        if (!layerFits(profile, e.middle) || !layerFits(profile, e.outer))
            return false;
    return true;
}

int workerCount(const RenderServerConfig& c) {
    constexpr int kMaxWorkers = 64;
    if (c.workers > 0)
        return std::min(c.workers, kMaxWorkers);
    return c.core >= 0 ? 1 : std::clamp(static_cast<int>(allowedCores().size()), 1, kMaxWorkers);
}

}  // namespace

struct RenderServer::Impl final : net::ServerHandler {
    RenderServerConfig config;
    Clock* clock = &SteadyClock::instance();  // config.clock, or the steady clock
    std::shared_ptr<const Scene> scene;
    std::unique_ptr<net::Server> server;
    std::unique_ptr<SharedPeriphery> sharing;  // null when off
    int worker_count = 1;
    std::vector<std::thread> workers;

    mutable std::mutex mutex;
    std::condition_variable cv;
    std::map<net::ClientId, std::shared_ptr<SessionState>> clients;
    // Every session in admission order, the ended ones too (at most kMaxEndedSessions).
    std::deque<std::shared_ptr<SessionState>> sessions;
    size_t ended_sessions = 0;
    net::ClientId last_served = 0;
    bool stopping = false;
    RenderServerStats stats;
    double cpu_ms_first_frame = 0.0, cpu_ms_last_frame = 0.0;  // processCpuMs() at their ends
    std::deque<ServerFrameRecord> records;                     // guarded by mutex
    // The measured service time per headset-frame: the mean of the first measure_frames, then
    // a moving average over about as many.
    uint64_t cost_frames = 0;
    double cost_ms = 0.0;
    std::mutex on_frame_mutex;  // config.on_frame is called one worker at a time

    // Start-up handshake with the workers.
    int ready_workers = 0;
    std::string start_error;

    void onClientConnected(net::ClientId id) override {
        auto s = std::make_shared<SessionState>();
        s->stats.client = id;
        s->admitted_ns = clock->nowNs();
        if (sharing)
            sharing->join(id);
        std::lock_guard lock(mutex);
        clients[id] = s;
        sessions.push_back(std::move(s));
    }
    void onClientGone(net::ClientId id) override {
        if (sharing)
            sharing->forget(id);
        Encoders released;  // destroyed after the lock (x264 takes its time)
        std::lock_guard lock(mutex);
        auto it = clients.find(id);
        if (it == clients.end())
            return;
        SessionState& s = *it->second;
        s.ended_ns = clock->nowNs();
        s.stats.connected = false;
        // An ended session keeps its counters, not its encoders (a worker serving its last
        // frame lets them go when it is done).
        if (!s.in_service)
            released = std::exchange(s.encoders, {});
        clients.erase(it);
        // Forget the oldest ended sessions beyond the bound.
        for (++ended_sessions; ended_sessions > kMaxEndedSessions; --ended_sessions)
            sessions.erase(std::find_if(sessions.begin(), sessions.end(),
                                        [](const auto& x) { return x->ended_ns != 0; }));
    }
    void onFrameRequest(net::ClientId id, const net::FrameRequest& request) override {
        {
            std::lock_guard lock(mutex);
            ++stats.requests;
            auto it = clients.find(id);
            if (it == clients.end())
                return;
            SessionState& s = *it->second;
            ++s.stats.frames_requested;
            s.pending.push_back({request, clock->nowNs()});
            while (s.pending.size() > std::max<size_t>(config.max_pending_requests, 1)) {
                s.pending.pop_front();
                ++stats.requests_dropped;
                ++s.stats.frames_dropped;
            }
        }
        cv.notify_one();
    }
    void onKeyFrameRequest(net::ClientId id, const net::KeyFrameRequest& request) override {
        std::lock_guard lock(mutex);
        ++stats.key_frame_requests;
        auto it = clients.find(id);
        if (it != clients.end())
            it->second->key_frame_mask.fetch_or(request.stream_mask);
    }

    // The cost admission goes by, and where it came from. Under mutex.
    std::pair<double, const char*> frameCostLocked() const {
        const AdmissionConfig& a = config.admission;
        if (a.measure_frames > 0 && cost_frames >= uint64_t(a.measure_frames))
            return {cost_ms, "measured"};
        if (a.frame_cost_ms > 0.0)
            return {a.frame_cost_ms, "calibration"};
        return {0.0, "none"};
    }

    net::Admission onAdmission(int admitted) override {
        std::lock_guard lock(mutex);
        const double cost = frameCostLocked().first;
        std::string why = admissionRefusal(config.admission, admitted, worker_count, cost,
                                           config.profile.refresh_hz);
        return {why.empty(), std::move(why)};
    }

    // The next frame to serve: the first ready session (a request queued, no worker on it)
    // after the one served last, in session order — round robin; null when stopping.
    std::shared_ptr<SessionState> next(net::ClientId& id, Queued& q) {
        std::unique_lock lock(mutex);
        for (;;) {
            if (stopping)
                return nullptr;
            auto it = clients.upper_bound(last_served);
            for (size_t n = 0; n < clients.size(); ++n, ++it) {
                if (it == clients.end())
                    it = clients.begin();
                SessionState& s = *it->second;
                if (s.in_service || s.pending.empty())
                    continue;
                id = it->first;
                q = std::move(s.pending.front());
                s.pending.pop_front();
                s.in_service = true;
                last_served = id;
                return it->second;
            }
            cv.wait(lock);
        }
    }

    // One request being served: what a worker stamps and counts while it works.
    struct Work {
        net::ClientId id = 0;
        SessionState* state = nullptr;
        const net::FrameRequest* req = nullptr;
        uint8_t key_mask = 0;
        ServerFrameRecord rec;
        RenderServerStats delta;
        int layers_planned = 0, layers_encoded = 0;
        int64_t render_start_ns = 0, render_end_ns = 0;
    };
    // A worker's images, reused from request to request.
    struct Images {
        ImageRgba8 image, outer, scratch;
    };

    // Pins the thread, makes the worker's renderer and uploads the scene, then tells start()
    // how it went; null when it failed.
    std::unique_ptr<Renderer> startRenderer() {
        if (config.core >= 0) {
            if (auto st = pinCurrentThread(config.core); !st)
                std::fprintf(stderr, "qvr server: %s (running unpinned)\n", st.error().c_str());
        }
        auto renderer = config.renderer();
        Status upload =
            renderer ? (*renderer)->upload(*scene) : Status(makeError(renderer.error()));
        {
            std::lock_guard lock(mutex);
            if (!upload && start_error.empty())
                start_error = upload.error();
            ++ready_workers;
        }
        cv.notify_all();
        if (!upload)
            return nullptr;
        return std::move(*renderer);
    }

    // A worker: its own renderer (an OpenGL context is current on one thread) serving whichever
    // session is ready next.
    void workerLoop() {
        std::unique_ptr<Renderer> renderer = startRenderer();
        if (!renderer)
            return;
        Images images;
        net::ClientId id = 0;
        Queued q;
        ServerFrameStamps stamps;
        while (std::shared_ptr<SessionState> state = next(id, q)) {
            serve(*renderer, images, id, *state, q.request, q.queued_ns, stamps);
            Encoders released;
            bool more = false;
            {
                std::lock_guard lock(mutex);
                state->in_service = false;
                if (state->ended_ns != 0)
                    released = std::exchange(state->encoders, {});
                more = !state->pending.empty();
            }
            if (more)
                cv.notify_one();  // its next frame may go to another worker
        }
    }

    // Renders, encodes and sends every layer of one request.
    void serve(Renderer& r, Images& images, net::ClientId id, SessionState& state,
               const net::FrameRequest& req, int64_t queued_ns, ServerFrameStamps& stamps) {
        stamps.client = id;
        stamps.frame_id = req.frame_id;
        stamps.client_send_ns = req.client_send_ns;
        stamps.queued_ns = queued_ns;
        stamps.start_ns = clock->nowNs();
        stamps.layers.clear();
        Work w;
        w.id = id;
        w.state = &state;
        w.req = &req;
        w.rec.client = id;
        w.rec.frame_id = req.frame_id;
        w.rec.e1_deg = req.e1_deg;
        w.rec.received_ns = queued_ns;
        w.rec.start_ns = stamps.start_ns;
        const LayerPlan plan = net::layerPlanOf(req);
        if (!planFits(config.profile, plan)) {
            std::lock_guard lock(mutex);
            ++stats.requests_invalid;
            ++state.stats.frames_dropped;
            return;
        }
        if (sharing)
            sharing->noteRequest(id, req.pose, plan);
        w.key_mask = state.key_frame_mask.exchange(0);
        for (int eye = 0; eye < 2; ++eye) {
            const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
            if (config.one_pass_periphery && onePassPays(layers))
                renderEyeInOnePass(r, images, plan, eye, w, stamps);
            else
                renderEyeByLayer(r, images, plan, eye, layers, w, stamps);
        }
        if (config.on_frame) {
            stamps.end_ns = clock->nowNs();
            std::lock_guard lock(on_frame_mutex);
            config.on_frame(stamps);
        }
        w.rec.done_ns = clock->nowNs();
        record(w);
    }

    // A render's fragments onto its stream's; a render that counted none leaves it uncounted.
    static void countFragments(ServerFrameRecord& rec, uint8_t sid, const RenderStats& rs) {
        if (!rs.statistics || rec.fragments[sid] < 0)
            rec.fragments[sid] = -1;
        else
            rec.fragments[sid] += int64_t(rs.fragment_invocations);
    }

    // An eye's middle and outer layers from one geometry pass.
    void renderEyeInOnePass(Renderer& r, Images& images, const LayerPlan& plan, int eye, Work& w,
                            ServerFrameStamps& stamps) {
        w.layers_planned += 2;
        w.render_start_ns = clock->nowNs();
        auto rs = renderPeriphery(r, config.profile, plan, w.req->pose, static_cast<Eye>(eye),
                                  images.image, images.outer, images.scratch);
        w.render_end_ns = clock->nowNs();
        w.delta.render_ms_total += double(w.render_end_ns - w.render_start_ns) * 1e-6;
        if (!rs) {
            w.delta.render_failures += 2;
            return;
        }
        const uint8_t mid = net::streamId(eye, net::Layer::kMiddle);
        w.rec.render_ms[mid] += rs->render_ms;
        w.rec.readback_ms[mid] += rs->readback_ms;
        w.rec.triangles[mid] += rs->primitives_generated;
        countFragments(w.rec, mid, *rs);
        w.delta.readback_ms_total += rs->readback_ms;
        w.delta.layers_rendered += 2;
        ++w.delta.periphery_passes;
        send(w, stamps, net::streamId(eye, net::Layer::kMiddle), images.image);
        send(w, stamps, net::streamId(eye, net::Layer::kOuter), images.outer);
    }

    // An eye's middle and outer layers, each from its own sub-frustum.
    void renderEyeByLayer(Renderer& r, Images& images, const LayerPlan& plan, int eye,
                          const EyeLayers& layers, Work& w, ServerFrameStamps& stamps) {
        for (net::Layer layer : {net::Layer::kMiddle, net::Layer::kOuter}) {
            const LayerKind kind =
                layer == net::Layer::kMiddle ? LayerKind::kMiddle : LayerKind::kOuter;
            if (layerOf(layers, kind).empty())
                continue;
            ++w.layers_planned;
            w.render_start_ns = clock->nowNs();
            auto rs = sharing
                          ? renderShareable(r, images, plan, static_cast<Eye>(eye), kind, w)
                          : renderLayer(r, config.profile, plan, w.req->pose, static_cast<Eye>(eye),
                                        kind, images.image, CameraOptions{}, config.holes);
            w.render_end_ns = clock->nowNs();
            w.delta.render_ms_total += double(w.render_end_ns - w.render_start_ns) * 1e-6;
            if (!rs) {
                ++w.delta.render_failures;
                continue;
            }
            const uint8_t sid = net::streamId(eye, layer);
            w.rec.render_ms[sid] += rs->render_ms;
            w.rec.readback_ms[sid] += rs->readback_ms;
            w.rec.triangles[sid] += rs->primitives_generated;
            countFragments(w.rec, sid, *rs);
            w.delta.readback_ms_total += rs->readback_ms;
            ++w.delta.layers_rendered;
            send(w, stamps, sid, images.image);
        }
    }

    // A middle or outer layer into images.image with sharing on: another member's shared render
    // reduced to this headset's layer; or its own beside such a candidate when a measurement is
    // due; or the group's layer, rendered, kept for the others and reduced; or its own alone,
    // kept when another headset may come by its pose.
    Expected<RenderStats> renderShareable(Renderer& r, Images& images, const LayerPlan& plan,
                                          Eye eye, LayerKind kind, const Work& w) {
        const Pose& pose = w.req->pose;
        const LayerRect& mine = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
        SharedPeriphery::Decision d =
            sharing->decide(w.id, eye, kind, pose, plan, config.profile, config.holes);
        switch (d.action) {
            case SharedPeriphery::Action::kReuse:
                images.image = std::move(d.image);
                return RenderStats{};
            case SharedPeriphery::Action::kRenderShared: {
                auto rs = renderLayer(r, config.profile, d.shared.plan, pose, eye, kind,
                                      images.outer, CameraOptions{}, d.shared.holes);
                if (!rs)
                    return rs;
                reduceSharedLayer(images.outer,
                                  layerOf(d.shared.plan.eyes[static_cast<size_t>(eye)], kind), mine,
                                  images.image, config.profile, pose.orientation, pose.orientation);
                sharing->store(w.id, eye, kind, pose, d.shared, images.outer);
                return rs;
            }
            case SharedPeriphery::Action::kMeasure:
            case SharedPeriphery::Action::kOwn:
                break;
        }
        auto rs = renderLayer(r, config.profile, plan, pose, eye, kind, images.image,
                              CameraOptions{}, config.holes);
        if (!rs)
            return rs;
        sharing->countOwn(kind);
        if (d.keep)
            sharing->store(w.id, eye, kind, pose, SharedLayer{plan, config.holes}, images.image);
        if (d.action == SharedPeriphery::Action::kMeasure)
            sharing->measured(
                w.id, eye, kind,
                layerSsimByBand(config.profile, plan, eye, kind, d.image, images.image,
                                sharing->config().band_deg, shownBeyondDeg(plan, eye, kind)));
        return rs;
    }

    // Where the compositor starts to show a layer: beyond the finer layer's disc (the outer
    // layer beyond the fovea's when there is no middle layer).
    double shownBeyondDeg(const LayerPlan& plan, Eye eye, LayerKind kind) const {
        if (kind == LayerKind::kOuter && plan.eyes[static_cast<size_t>(eye)].middle.empty())
            return plan.e1_deg;
        return layerHoleDeg(config.profile, plan, eye, kind, LayerHoles{.enabled = true});
    }

    // Encodes one layer with its stream's encoder and hands it to the transport, which never
    // blocks: a session whose media queue is full loses this stream, not the worker's time.
    void send(Work& w, ServerFrameStamps& stamps, uint8_t sid, const ImageRgba8& layer_image) {
        w.rec.pixels[sid] = int64_t(layer_image.width()) * layer_image.height();
        auto& enc = w.state->encoders[sid];
        if (!enc) {
            auto made = makeVideoEncoder(config.codec);
            if (!made) {
                ++w.delta.encode_failures;
                return;
            }
            enc = std::move(*made);
        }
        if (w.key_mask & (1u << sid))
            enc->requestKeyframe();
        auto encoded = enc->encode(layer_image);
        if (!encoded) {
            ++w.delta.encode_failures;
            return;
        }
        ++w.layers_encoded;
        w.delta.encode_ms_total += encoded->encode_ms;
        w.rec.encode_ms[sid] += encoded->encode_ms;
        w.rec.bytes[sid] += static_cast<int64_t>(encoded->bytes.size());
        const int64_t encode_end_ns = clock->nowNs();
        const bool key = encoded->is_keyframe;
        if (config.on_frame)  // stamped before the transport can deliver it
            stamps.layers.push_back({sid, w.render_start_ns, w.render_end_ns, encode_end_ns,
                                     clock->nowNs(), w.rec.pixels[sid], w.rec.fragments[sid]});
        // The server's time on the frame so far: the headset's LIWC learns S from it.
        stampServerUs(encoded->bytes, static_cast<uint32_t>(std::clamp<int64_t>(
                                          (encode_end_ns - w.rec.start_ns) / 1000, 0, 0xFFFFFFFF)));
        const int64_t send_start_ns = clock->nowNs();
        if (server->sendStream(w.id, w.req->frame_id, sid, key, std::move(encoded->bytes)))
            ++w.delta.streams_sent;
        else
            ++w.delta.stream_send_failures;
        const double send_ms = double(clock->nowNs() - send_start_ns) * 1e-6;
        w.rec.send_ms[sid] += send_ms;
        w.delta.send_ms_total += send_ms;
    }

    // Adds the served frame to its session's counters and the measured cost. Under mutex.
    void countSessionFrame(const Work& w) {
        const RenderServerStats& d = w.delta;
        SessionStats& s = w.state->stats;
        const bool rendered = int(d.layers_rendered) == w.layers_planned;
        const bool encoded = rendered && w.layers_encoded == w.layers_planned;
        s.frames_rendered += rendered ? 1 : 0;
        s.frames_encoded += encoded ? 1 : 0;
        s.frames_sent += encoded && int(d.streams_sent) == w.layers_planned ? 1 : 0;
        s.streams_sent += d.streams_sent;
        s.stream_send_failures += d.stream_send_failures;
        s.render_ms_total += d.render_ms_total;
        s.encode_ms_total += d.encode_ms_total;
        const double service_ms = double(w.rec.done_ns - w.rec.start_ns) * 1e-6;
        s.service_ms_total += service_ms;
        s.queue_ms_total += double(w.rec.start_ns - w.rec.received_ns) * 1e-6;
        const int n = std::max(config.admission.measure_frames, 1);
        ++cost_frames;
        const double weight =
            cost_frames <= uint64_t(n) ? 1.0 / double(cost_frames) : 2.0 / (double(n) + 1.0);
        cost_ms += weight * (service_ms - cost_ms);
    }

    // Keeps the frame's record and adds its counts to the server's and its session's.
    void record(const Work& w) {
        const RenderServerStats& delta = w.delta;
        const double cpu_ms = processCpuMs();  // a system call: outside the server's lock
        std::lock_guard lock(mutex);
        if (config.max_frame_records > 0)
            records.push_back(w.rec);
        while (records.size() > config.max_frame_records)
            records.pop_front();
        ++stats.frames_rendered;
        // CPU time from the end of the first frame (lazy start-up) to the end of the last.
        (stats.frames_rendered == 1 ? cpu_ms_first_frame : cpu_ms_last_frame) = cpu_ms;
        stats.layers_rendered += delta.layers_rendered;
        stats.periphery_passes += delta.periphery_passes;
        stats.streams_sent += delta.streams_sent;
        stats.stream_send_failures += delta.stream_send_failures;
        stats.render_failures += delta.render_failures;
        stats.encode_failures += delta.encode_failures;
        stats.render_ms_total += delta.render_ms_total;
        stats.encode_ms_total += delta.encode_ms_total;
        stats.readback_ms_total += delta.readback_ms_total;
        stats.send_ms_total += delta.send_ms_total;
        countSessionFrame(w);
    }

    // Asks every worker to stop and joins them.
    void stopWorkers() {
        {
            std::lock_guard lock(mutex);
            stopping = true;
        }
        cv.notify_all();
        for (std::thread& t : workers)
            if (t.joinable())
                t.join();
    }

    // Starts the workers and waits until each has its renderer; an error when one has none.
    Status startWorkers() {
        worker_count = workerCount(config);
        stats.workers = worker_count;
        for (int i = 0; i < worker_count; ++i)
            workers.emplace_back([this] { workerLoop(); });
        std::string error;
        {
            std::unique_lock lock(mutex);
            cv.wait(lock, [this] { return ready_workers == worker_count; });
            error = start_error;
        }
        if (error.empty())
            return {};
        stopWorkers();
        return makeError(error);
    }
};

Expected<std::unique_ptr<RenderServer>> RenderServer::start(RenderServerConfig config,
                                                            std::shared_ptr<const Scene> scene) {
    if (!scene)
        return makeError("render server: no scene");
    if (auto st = validateCodecConfig(config.codec); !st)
        return makeError("render server: " + st.error());
    auto impl = std::make_unique<Impl>();
    impl->config = std::move(config);
    if (impl->config.clock)
        impl->clock = impl->config.clock;
    // Clients must stream with our codec at our display profile (refused in the handshake).
    const HmdProfile& hp = impl->config.profile;
    impl->config.net.settings = net::makeSessionSettings(impl->config.codec.backend, hp.name,
                                                         hp.width_px, hp.height_px, hp.refresh_hz);
    impl->scene = std::move(scene);
    if (impl->config.share_periphery.mode != SharePeripheryMode::kOff)
        impl->sharing = std::make_unique<SharedPeriphery>(impl->config.share_periphery);
    Impl* p = impl.get();
    if (Status st = p->startWorkers(); !st)
        return makeError("render server: " + st.error());
    auto server = net::Server::start(p->config.net, *p);
    if (!server) {
        p->stopWorkers();
        return makeError("render server: " + server.error());
    }
    p->server = std::move(*server);
    return std::unique_ptr<RenderServer>(new RenderServer(std::move(impl)));
}

RenderServer::RenderServer(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}

RenderServer::~RenderServer() {
    stop();
}

void RenderServer::stop() {
    if (!m_impl)
        return;
    m_impl->stopWorkers();
    if (m_impl->server)
        m_impl->server->stop();
}

uint16_t RenderServer::port() const {
    return m_impl->server ? m_impl->server->port() : 0;
}

RenderServerStats RenderServer::stats() const {
    RenderServerStats s;
    {
        const Impl& m = *m_impl;
        std::lock_guard lock(m.mutex);
        s = m.stats;
        const auto [cost_ms, source] = m.frameCostLocked();
        s.frame_cost_ms = cost_ms;
        s.frame_cost_source = source;
        s.min_fps = m.config.admission.min_fps;
        if (s.frames_rendered > 1)
            s.cpu_ms_per_frame =
                (m.cpu_ms_last_frame - m.cpu_ms_first_frame) / double(s.frames_rendered - 1);
        const int64_t now_ns = m.clock->nowNs();
        for (const auto& x : m.sessions) {
            SessionStats st = x->stats;
            st.connected_s =
                double((x->ended_ns != 0 ? x->ended_ns : now_ns) - x->admitted_ns) * 1e-9;
            s.sessions.push_back(st);
        }
    }
    s.share_periphery = m_impl->sharing ? m_impl->sharing->stats()
                                        : SharedPeriphery(m_impl->config.share_periphery).stats();
    if (m_impl->server)
        s.net = m_impl->server->stats();
    return s;
}

std::vector<ServerFrameRecord> RenderServer::frameRecords() const {
    std::lock_guard lock(m_impl->mutex);
    return {m_impl->records.begin(), m_impl->records.end()};
}

size_t RenderServer::clients() const {
    std::lock_guard lock(m_impl->mutex);
    return m_impl->clients.size();
}

}  // namespace qvr::runtime
