// The headset (paper Fig. 4, §3–4): per frame it samples head pose and gaze from traces, asks the
// fovea policy for e1 before rendering (LIWC reads the frame's fovea-cone triangles and the
// throughput measured from acknowledgements), requests the periphery from the render server,
// renders the fovea locally, decodes the periphery streams as they arrive, and composes with
// UCA for the newest pose, paced to the display's vsync. Late or lost remote layers make it
// re-warp the newest layers it has (frame reuse); a server that is gone makes it render
// everything locally and reconnect when it returns.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "qvr/codec/video_codec.h"
#include "qvr/core/design.h"
#include "qvr/core/expected.h"
#include "qvr/core/image.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/net/auth.h"
#include "qvr/net/client.h"
#include "qvr/runtime/pacing.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/telemetry.h"
#include "qvr/scene/scene.h"
#include "qvr/scene/triangle_bvh.h"
#include "qvr/trace/gaze_model.h"
#include "qvr/trace/pose_trace.h"
#include "qvr/workload/trace_io.h"

namespace qvr::runtime {

// The display seam: receives what the headset scanned out (both eyes, after UCA).
class DisplaySink {
public:
    virtual ~DisplaySink() = default;
    virtual void onScanout(const FrameTelemetry& frame, const LayerPlan& shown_plan,
                           const std::array<ImageRgba8, 2>& eyes) = 0;
};

struct HeadsetTraces {
    PoseTrace motion;  // sampled at the frame's content time, k / refresh_hz
    GazeTrace gaze;
};

struct HeadsetConfig {
    Design design = Design::Qvr;
    HmdProfile profile;
    CodecConfig codec;  // the decoders' backend must match the server's encoders
    RendererFactory renderer = glRendererFactory();
    std::string host = "127.0.0.1";
    uint16_t port = 0;
    net::PresharedKey key;
    int frames = 300;
    int core = -1;  // pin the headset thread (and the threads it creates) to this core
    // A frame's remote layers that have not all been decoded this long after the request are
    // late: the display re-warps the newest layers it has instead (§4.2 frame reuse).
    double remote_timeout_ms = 250.0;
    int connect_timeout_ms = 500;
    int reconnect_interval_ms = 250;
    double fixed_e1_deg = kFfrE1Deg;  // Design::Ffr and Design::Fixed
    // Frames in flight (docs/RUNTIME.md): 1 runs each frame to its scan-out before the next
    // frame's pose is sampled; 2 samples frame n+1 and sends its request before frame n's fovea
    // renders, so the server renders n+1 while the headset finishes n (paper Fig. 4's overlap
    // across frames). The policy then decides n+1 before it has observed n.
    int pipeline_depth = 2;
    // The first frames are left out of the summary's statistics (telemetry.h DesignSummary):
    // the session's start-up and the policy's first decisions. (Timings of the first
    // pipeline_depth frames, requested before any completed, never reach the policy's fits.)
    int warmup_frames = 0;
    // Scan-out: false queues the composed frame for its vsync slot and goes on with the next
    // (a two-image swapchain, VsyncPacer::queueForScanout); true waits for the slot first
    // (one frame's composition never overlaps the previous one's scan-out).
    bool wait_for_vsync = false;
    // The level of detail the fovea is drawn at (its renderer's lod_error_px): LIWC's triangle
    // rings count what that level draws.
    float lod_error_px = 1.0f;
    // LIWC's triangle rings from the draw clusters at that level of detail (cheap, what is
    // drawn) or, when false, from the scene's BVH (every triangle, cost growing with e1).
    bool cluster_ring_counts = true;
    Clock* clock = nullptr;  // steady clock when null
    DisplaySink* display = nullptr;
    // Records each frame's WorkloadFrame when set: held with the frame's telemetry and written
    // as it retires (at the session's end when keep_frames is 0), off the frames' path.
    WorkloadTraceWriter* workload = nullptr;
    std::function<void(int64_t frame)> before_frame;  // test hook, called at each frame start
    // Every frame's telemetry, once final, in order (e.g. a CSV written as the session runs).
    std::function<void(const FrameTelemetry&)> frame_sink;
    // 0: HeadsetResult::frames holds every frame (qvr run). N: only the newest N (at least 64)
    // stay in memory, the rest go to frame_sink and the summary as they age, so a session of
    // any length runs in flat memory (qvr client).
    size_t keep_frames = 0;
    // When set and true (e.g. from a SIGINT handler), no new frame starts; the frames already
    // started are finished, so the result holds every frame shown and nothing half-done.
    const std::atomic<bool>* stop = nullptr;
};

struct HeadsetStats {
    uint64_t streams_received = 0;
    uint64_t streams_decoded = 0;
    uint64_t streams_lost = 0;
    uint64_t decode_failures = 0;
    uint64_t streams_discarded = 0;  // decoded for the reference chain, frame already shown
    uint64_t key_frame_requests = 0;
    uint64_t late_frames = 0;
    // Frames that waited one refresh, not the wait limit, because the server had sent nothing
    // for a whole limit (stalled, killed, or its link dead): the display keeps its rate.
    uint64_t silent_server_frames = 0;
    // Frames shown with an older periphery at once because the window of outstanding requests
    // was full (the link behind: qvr/core/request_window.h); none asked the server.
    uint64_t requests_withheld = 0;
    uint64_t connects = 0;
    uint64_t connect_failures = 0;
    uint64_t disconnects = 0;
    uint64_t compose_failures = 0;
    uint64_t render_failures = 0;
    int core = -1;  // where the loop ran at the end
    net::ClientStats net;
};

struct HeadsetResult {
    int64_t origin_ns = 0;               // the pacing clock at the run's start: telemetry's 0
    std::vector<FrameTelemetry> frames;  // every frame, or the newest keep_frames
    HeadsetStats stats;
    DesignSummary summary;
};

// Runs config.frames frames on the calling thread. Errors only for set-up (renderer, empty
// traces); per-frame failures are counted and the loop continues.
Expected<HeadsetResult> runHeadset(const HeadsetConfig& config, std::shared_ptr<const Scene> scene,
                                   std::shared_ptr<const TriangleBvh> bvh,
                                   const HeadsetTraces& traces);

// The frames the headset holds pending (asked of the server, not yet shown): at most this many,
// and at most this many bytes of their images, the oldest dropped first. The frame the server
// is rendering is the oldest it still owes, so the bound must outlast a slow server's frame
// (docs/RUNTIME.md step 6); the bytes bound the memory, each entry holding its fovea.
inline constexpr size_t kMaxPendingFrames = 64;
inline constexpr size_t kMaxPendingImageBytes = size_t(64) << 20;

// How many of the oldest pending frames to drop so that at most max_frames stay and their
// images hold at most max_bytes; the newest always stays. bytes: each one's images, oldest first.
size_t pendingFramesToDrop(std::span<const size_t> bytes, size_t max_frames, size_t max_bytes);

// The plan of whole-frame streaming: one full-resolution "middle" layer per eye, nothing local.
LayerPlan wholeFramePlan(const LayerPlanner& planner, const Gaze& gaze);

}  // namespace qvr::runtime
