// The render server (paper §3.2, Fig. 7): for each frame request of each headset, renders the
// middle and outer layers of both eyes for the request's pose, gaze and layer plan, encodes each
// as its own video stream and hands each to the transport the moment it is encoded. Serves
// several headsets on a pool of render workers (docs/RUNTIME.md §Serving many headsets): each
// headset has a bounded request queue and its own encoders, the workers take ready headsets in
// turn, and a headset is admitted only while the admitted ones keep the frame-rate floor.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "qvr/codec/video_codec.h"
#include "qvr/core/clock.h"
#include "qvr/core/expected.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/net/server.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/shared_periphery.h"
#include "qvr/scene/scene.h"

namespace qvr::runtime {

// Renderers are made on the thread that uses them (an OpenGL context is current on one thread).
using RendererFactory = std::function<Expected<std::unique_ptr<Renderer>>()>;
RendererFactory glRendererFactory(GlRendererOptions options = {});
RendererFactory nullRendererFactory();

// When and how long the server worked on one request, on the server's steady clock (ns since
// the clock's epoch, CLOCK_MONOTONIC): for timelines (trace.json, docs/RUNTIME.md).
struct ServerFrameStamps {
    uint64_t client = 0;          // the transport's id of the headset
    uint32_t frame_id = 0;        // the request's frame id
    uint64_t client_send_ns = 0;  // echoed from the request (the headset's pose sample)
    int64_t queued_ns = 0;        // the request was queued
    int64_t start_ns = 0;         // the render thread took it
    int64_t end_ns = 0;           // its last stream was handed to the transport
    struct Layer {
        uint8_t stream_id = 0;
        int64_t render_start_ns = 0;
        int64_t render_end_ns = 0;
        int64_t encode_end_ns = 0;
        int64_t sent_ns = 0;  // about to be handed to the transport (and its link emulator)
        // The layer's image and the fragments its render shaded (its overdraw; -1: not counted;
        // a one-pass eye's middle layer carries both layers').
        int64_t pixels = 0;
        int64_t fragments = -1;
    };
    std::vector<Layer> layers;
};

// Admission by capacity (docs/RUNTIME.md §Admission): a headset is refused (Bye(over capacity),
// the client prints why and gives up) when admitting it would take the admitted ones below
// min_fps by the server's cost per headset-frame.
struct AdmissionConfig {
    double min_fps = 0.0;  // the floor; 0: admit up to net.max_clients, as without admission
    // A headset-frame's service time on one worker (render, read-back and encode of its layers)
    // from the calibration (the hardware file's runtime.speed_reference_server_ms); 0: unknown
    // until measured.
    double frame_cost_ms = 0.0;
    // Served frames after which the server's own mean service time replaces frame_cost_ms.
    int measure_frames = 30;
};

// Per-headset frame rate the server sustains for `headsets` sessions on `workers` workers at
// `frame_cost_ms` a headset-frame: a session's frames are served one at a time, so one worker
// at most each, and the workers' time is shared evenly; never above the display's refresh.
double sustainedFps(int headsets, int workers, double frame_cost_ms, double refresh_hz);

// The admission verdict for one more headset beside `admitted` (empty: admit; else why not).
// With the cost unknown (≤ 0) a headset is admitted while each can have a worker of its own.
std::string admissionRefusal(const AdmissionConfig& a, int admitted, int workers,
                             double frame_cost_ms, double refresh_hz);

struct RenderServerConfig {
    net::ServerOptions net;
    HmdProfile profile;  // must be the headsets' profile: requests larger than it are refused
    CodecConfig codec;
    RendererFactory renderer = glRendererFactory();
    int core = -1;  // pin the render workers to this core (-1: no pinning)
    // Render workers, each with its own renderer (GL context) and images; 0: one per core the
    // process may run on (sched_getaffinity), or 1 when pinned to `core`.
    int workers = 0;
    AdmissionConfig admission;
    // The clock of the server's stamps and times (steady clock when null; tests pass a fake).
    Clock* clock = nullptr;
    // Requests waiting per headset; a newer request pushes the oldest out (it would be late).
    size_t max_pending_requests = 2;
    // Render an eye's middle and outer layers in one geometry pass (render/periphery_pass.h)
    // instead of each layer's own sub-frustum. It pays when geometry dominates (no LOD, small
    // displays); with LOD at the paper's display the extended grid's fill costs more than the
    // second pass saves (docs/RUNTIME.md), so it is off by default.
    bool one_pass_periphery = false;
    // Served frames kept for frameRecords(), newest last (0: none, so a long-running server
    // that nobody asks for them holds no per-frame memory).
    size_t max_frame_records = 100'000;
    // Called on a render worker after each rendered request (keep it cheap; workers call it
    // one at a time).
    std::function<void(const ServerFrameStamps&)> on_frame;
    // Leave out of each periphery layer the clusters the compositor takes from a finer layer
    // only (render/renderer.h LayerHoles): a larger fovea then costs the server less.
    LayerHoles holes{.enabled = true};
    // One outer layer for headsets whose poses are close, one middle layer for those whose gazes
    // are close too (docs/RUNTIME.md §Shared periphery); off by default. Eyes rendered in one
    // pass (one_pass_periphery) are not shared.
    SharePeripheryConfig share_periphery;
};

// One served frame, for the per-frame server log (`qvr server --frames-csv`): where the server's
// time went, layer by layer. Times in ms; index = stream id (eye · 2 + layer).
struct ServerFrameRecord {
    uint64_t client = 0;  // the session (one per design in `qvr run`)
    uint32_t frame_id = 0;
    double e1_deg = 0.0;
    int64_t received_ns = 0;  // the request arrived (steady clock)
    int64_t start_ns = 0;     // the render thread took it
    int64_t done_ns = 0;      // the last layer was handed to the transport
    std::array<int64_t, 4> pixels{};
    std::array<uint64_t, 4> triangles{};  // submitted after culling and LOD
    std::array<int64_t, 4> fragments{};   // fragment shader invocations (-1: not counted)
    std::array<double, 4> render_ms{};    // commands to glFinish
    std::array<double, 4> readback_ms{};
    std::array<double, 4> encode_ms{};
    std::array<double, 4> send_ms{};
    std::array<int64_t, 4> bytes{};
};

// One headset's session, counted by the server (its stats JSON's "sessions" list).
struct SessionStats {
    uint64_t client = 0;  // the transport's session id
    bool connected = true;
    double connected_s = 0.0;       // from its admission to its end, or to now
    uint64_t frames_requested = 0;  // frame requests received
    uint64_t frames_dropped = 0;    // pushed out of its full queue (newer ones came) or invalid
    uint64_t frames_rendered = 0;   // served, every layer rendered
    uint64_t frames_encoded = 0;    // served, every layer encoded
    uint64_t frames_sent = 0;       // served, every layer's stream taken by the transport
    uint64_t streams_sent = 0;
    uint64_t stream_send_failures = 0;  // its media queue was full (it does not keep up) or gone
    double render_ms_total = 0.0;       // render + read-back, wall clock
    double encode_ms_total = 0.0;
    double service_ms_total = 0.0;  // taken by a worker to its last layer handed over
    double queue_ms_total = 0.0;    // waiting in its queue for a worker
};

struct RenderServerStats {
    uint64_t requests = 0;
    uint64_t requests_dropped = 0;  // pushed out of a full queue
    uint64_t requests_invalid = 0;  // a plan that does not fit the profile
    uint64_t frames_rendered = 0;
    uint64_t layers_rendered = 0;
    uint64_t periphery_passes = 0;  // eyes whose two layers came from one pass
    uint64_t streams_sent = 0;
    uint64_t stream_send_failures = 0;  // the transport's queue was full or the client gone
    uint64_t render_failures = 0;
    uint64_t encode_failures = 0;
    uint64_t key_frame_requests = 0;
    double render_ms_total = 0.0;  // render + read-back, wall clock
    double readback_ms_total = 0.0;
    double encode_ms_total = 0.0;
    double send_ms_total = 0.0;
    int workers = 0;
    // The process's CPU time (user + system, every thread: workers, the renderer's, the
    // transport's) per frame served, from the end of the first frame to the end of the last:
    // beside the wall-clock service times, which would overstate it were workers kept waiting.
    double cpu_ms_per_frame = 0.0;
    // What admission knew when asked: the cost per headset-frame and where it came from
    // ("calibration", "measured" or "none").
    double frame_cost_ms = 0.0;
    std::string frame_cost_source = "none";
    double min_fps = 0.0;
    // Every session, the ended ones too (the oldest ended ones beyond kMaxEndedSessions
    // forgotten), in the order they were admitted.
    std::vector<SessionStats> sessions;
    SharePeripheryStats share_periphery;
    net::ServerStats net;
};
inline constexpr size_t kMaxEndedSessions = 256;

// The pool, admission and per-session counters as the server's stats JSON carries them:
// {"workers", "cpu_ms_per_frame", "admission": {"min_fps", "frame_cost_ms", "frame_cost_source",
// "refused_capacity"}, "sessions": [{"client", "connected", "connected_s", "frames_requested",
// "frames_dropped", "frames_rendered", "frames_encoded", "frames_sent", "fps_sent",
// "streams_sent", "stream_send_failures", "render_ms_mean", "encode_ms_mean",
// "service_ms_mean", "queue_ms_mean"}, ...], "share_periphery": sharePeripheryJson()}
// (docs/RUNTIME.md §Serving many headsets, §Shared periphery).
nlohmann::json serverPoolJson(const RenderServerStats& s);

class RenderServer {
public:
    // Starts the render workers (each makes its renderer and uploads the scene on its own
    // thread) and then the transport.
    static Expected<std::unique_ptr<RenderServer>> start(RenderServerConfig config,
                                                         std::shared_ptr<const Scene> scene);
    ~RenderServer();
    RenderServer(const RenderServer&) = delete;
    RenderServer& operator=(const RenderServer&) = delete;

    // Closes every connection and joins the threads. Idempotent.
    void stop();
    uint16_t port() const;
    RenderServerStats stats() const;
    // The newest served frames, oldest first (at most config.max_frame_records).
    std::vector<ServerFrameRecord> frameRecords() const;
    size_t clients() const;

    struct Impl;

private:
    explicit RenderServer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

}  // namespace qvr::runtime
