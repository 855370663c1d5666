// The render server: a bounded request queue per headset, one render thread that renders,
// encodes and sends each periphery layer as soon as it is ready (paper Fig. 7's parallel streams).
#include "qvr/runtime/render_server.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "qvr/render/gl_renderer.h"
#include "qvr/render/periphery_pass.h"
#include "qvr/runtime/affinity.h"

namespace qvr::runtime {

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

namespace {

struct ClientState {
    struct Queued {
        net::FrameRequest request;
        int64_t queued_ns = 0;
    };
    std::deque<Queued> pending;  // guarded by Impl::mutex
    std::atomic<uint8_t> key_frame_mask{0};
    // Touched by the render thread only.
    std::array<std::unique_ptr<VideoEncoder>, net::kMaxStreams> encoders;
};

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

}  // namespace

struct RenderServer::Impl final : net::ServerHandler {
    RenderServerConfig config;
    Clock* clock = &SteadyClock::instance();  // config.clock, or the steady clock
    std::shared_ptr<const Scene> scene;
    std::unique_ptr<net::Server> server;
    std::thread render_thread;

    mutable std::mutex mutex;
    std::condition_variable cv;
    std::map<net::ClientId, std::shared_ptr<ClientState>> clients;
    net::ClientId last_served = 0;
    bool stopping = false;
    RenderServerStats stats;
    std::deque<ServerFrameRecord> records;  // guarded by mutex

    // Start-up handshake with the render thread.
    bool ready = false;
    std::string start_error;

    void onClientConnected(net::ClientId id) override {
        std::lock_guard lock(mutex);
        clients[id] = std::make_shared<ClientState>();
    }
    void onClientGone(net::ClientId id) override {
        std::lock_guard lock(mutex);
        clients.erase(id);
    }
    void onFrameRequest(net::ClientId id, const net::FrameRequest& request) override {
        {
            std::lock_guard lock(mutex);
            ++stats.requests;
            auto it = clients.find(id);
            if (it == clients.end())
                return;
            auto& q = it->second->pending;
            q.push_back({request, clock->nowNs()});
            while (q.size() > std::max<size_t>(config.max_pending_requests, 1)) {
                q.pop_front();
                ++stats.requests_dropped;
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

    // The next request, round robin over headsets; false when stopping.
    bool next(net::ClientId& id, std::shared_ptr<ClientState>& state, net::FrameRequest& req,
              int64_t& queued_ns) {
        std::unique_lock lock(mutex);
        for (;;) {
            if (stopping)
                return false;
            auto pick = clients.upper_bound(last_served);
            for (size_t n = 0; n < clients.size(); ++n) {
                if (pick == clients.end())
                    pick = clients.begin();
                if (!pick->second->pending.empty()) {
                    id = pick->first;
                    state = pick->second;
                    req = state->pending.front().request;
                    queued_ns = state->pending.front().queued_ns;
                    state->pending.pop_front();
                    last_served = id;
                    return true;
                }
                ++pick;
            }
            cv.wait(lock);
        }
    }

    // One request being served: what the render thread stamps and counts while it works.
    struct Work {
        net::ClientId id = 0;
        ClientState* state = nullptr;
        const net::FrameRequest* req = nullptr;
        uint8_t key_mask = 0;
        ServerFrameRecord rec;
        RenderServerStats delta;
        int64_t render_start_ns = 0, render_end_ns = 0;
    };
    // The render thread's images, reused from request to request.
    struct Images {
        ImageRgba8 image, outer, scratch;
    };

    // Pins the thread, makes the renderer and uploads the scene, then tells start() how it
    // went; null when it failed.
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
            if (!upload)
                start_error = upload.error();
            ready = true;
        }
        cv.notify_all();
        if (!upload)
            return nullptr;
        return std::move(*renderer);
    }

    void renderLoop() {
        std::unique_ptr<Renderer> renderer = startRenderer();
        if (!renderer)
            return;
        Images images;
        net::ClientId id = 0;
        std::shared_ptr<ClientState> state;
        net::FrameRequest req;
        int64_t queued_ns = 0;
        ServerFrameStamps stamps;
        while (next(id, state, req, queued_ns))
            serve(*renderer, images, id, *state, req, queued_ns, stamps);
    }

    // Renders, encodes and sends every layer of one request.
    void serve(Renderer& r, Images& images, net::ClientId id, ClientState& state,
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
            return;
        }
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
            config.on_frame(stamps);
        }
        w.rec.done_ns = clock->nowNs();
        record(w);
    }

    // An eye's middle and outer layers from one geometry pass.
    void renderEyeInOnePass(Renderer& r, Images& images, const LayerPlan& plan, int eye, Work& w,
                            ServerFrameStamps& stamps) {
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
            w.render_start_ns = clock->nowNs();
            auto rs = renderLayer(r, config.profile, plan, w.req->pose, static_cast<Eye>(eye), kind,
                                  images.image, CameraOptions{}, config.holes);
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
            w.rec.pixels[sid] = int64_t(images.image.width()) * images.image.height();
            w.delta.readback_ms_total += rs->readback_ms;
            ++w.delta.layers_rendered;
            send(w, stamps, sid, images.image);
        }
    }

    // Encodes one layer with its stream's encoder and hands it to the transport.
    void send(Work& w, ServerFrameStamps& stamps, uint8_t sid, const ImageRgba8& layer_image) {
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
        w.delta.encode_ms_total += encoded->encode_ms;
        w.rec.encode_ms[sid] += encoded->encode_ms;
        w.rec.bytes[sid] += static_cast<int64_t>(encoded->bytes.size());
        const int64_t encode_end_ns = clock->nowNs();
        const bool key = encoded->is_keyframe;
        if (config.on_frame)  // stamped before the transport can deliver it
            stamps.layers.push_back(
                {sid, w.render_start_ns, w.render_end_ns, encode_end_ns, clock->nowNs()});
        const int64_t send_start_ns = clock->nowNs();
        if (server->sendStream(w.id, w.req->frame_id, sid, key, std::move(encoded->bytes)))
            ++w.delta.streams_sent;
        else
            ++w.delta.stream_send_failures;
        const double send_ms = double(clock->nowNs() - send_start_ns) * 1e-6;
        w.rec.send_ms[sid] += send_ms;
        w.delta.send_ms_total += send_ms;
    }

    // Keeps the frame's record and adds its counts to the server's.
    void record(const Work& w) {
        const RenderServerStats& delta = w.delta;
        std::lock_guard lock(mutex);
        if (config.max_frame_records > 0)
            records.push_back(w.rec);
        while (records.size() > config.max_frame_records)
            records.pop_front();
        ++stats.frames_rendered;
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
    Impl* p = impl.get();
    impl->render_thread = std::thread([p] { p->renderLoop(); });
    {
        std::unique_lock lock(p->mutex);
        p->cv.wait(lock, [p] { return p->ready; });
    }
    if (!p->start_error.empty()) {
        p->render_thread.join();
        return makeError("render server: " + p->start_error);
    }
    auto server = net::Server::start(p->config.net, *p);
    if (!server) {
        {
            std::lock_guard lock(p->mutex);
            p->stopping = true;
        }
        p->cv.notify_all();
        p->render_thread.join();
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
    {
        std::lock_guard lock(m_impl->mutex);
        m_impl->stopping = true;
    }
    m_impl->cv.notify_all();
    if (m_impl->render_thread.joinable())
        m_impl->render_thread.join();
    if (m_impl->server)
        m_impl->server->stop();
}

uint16_t RenderServer::port() const {
    return m_impl->server ? m_impl->server->port() : 0;
}

RenderServerStats RenderServer::stats() const {
    RenderServerStats s;
    {
        std::lock_guard lock(m_impl->mutex);
        s = m_impl->stats;
    }
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
