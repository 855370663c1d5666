// The runtime end to end on 127.0.0.1 (issue 6): a render server and a headset through net's
// transport and link emulator. Small profiles and few frames keep each test to seconds.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <numeric>
#include <thread>
#include <vector>

#include "qvr/core/request_window.h"
#include "qvr/net/auth.h"
#include "qvr/net/protocol.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/pacing.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/session.h"
#include "qvr/scene/scene_loader.h"
#include "slow_renderer.h"

namespace qvr::runtime {
namespace {

using namespace std::chrono_literals;

net::PresharedKey keyA() {
    return net::PresharedKey::fromHex(std::string(64, 'a')).value();
}
net::PresharedKey keyB() {
    return net::PresharedKey::fromHex(std::string(64, 'b')).value();
}

struct World {
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<const TriangleBvh> bvh;
    HmdProfile profile;
    HeadsetTraces traces;
};

const World& world() {
    static const World w = [] {
        World x;
        SceneLoadOptions so;
        so.builtin_objects = 8;
        x.scene = std::make_shared<const Scene>(loadScene("builtin:room", so).value());
        x.bvh = std::make_shared<const TriangleBvh>(*x.scene);
        x.profile = runtimeProfileByName("small").value();
        // Head motion without the BVH package dependency: a slow yaw sweep.
        for (int i = 0; i <= 400; ++i) {
            Pose p = x.scene->spawns.empty() ? Pose{} : Pose{};
            if (!x.scene->spawns.empty())
                p.position_m = x.scene->spawns.front().position_m;
            p.orientation = quatFromEulerDeg({0.1 * i, 0.0, 0.0});
            x.traces.motion.samples.push_back({i * 1000.0 / 90.0, p});
        }
        GazeModelConfig gc;
        x.traces.gaze = generateGaze(gc, 7, 600).value();
        return x;
    }();
    return w;
}

RenderServerConfig serverConfig(const std::string& link, const std::string& codec,
                                bool gl = false) {
    RenderServerConfig c;
    c.net.key = keyA();
    c.net.link = qvr::loadLinkSpec(link).value();
    c.profile = world().profile;
    c.codec.backend = codec;
    c.renderer = gl ? glRendererFactory() : nullRendererFactory();
    return c;
}

HeadsetConfig headsetConfig(Design design, uint16_t port, const std::string& codec, int frames,
                            bool gl = false) {
    HeadsetConfig h;
    h.design = design;
    h.profile = world().profile;
    h.codec.backend = codec;
    h.renderer = gl ? glRendererFactory() : nullRendererFactory();
    h.port = port;
    h.key = keyA();
    h.frames = frames;
    h.connect_timeout_ms = 500;
    h.reconnect_interval_ms = 100;
    return h;
}

HeadsetResult runOn(const HeadsetConfig& h) {
    auto r = runHeadset(h, world().scene, world().bvh, world().traces);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error());
    return r.ok() ? std::move(*r) : HeadsetResult{};
}

bool glAvailable() {
    static const bool ok = GlRenderer::create().ok();
    return ok;
}

TEST(VsyncPacer, ScansOutAtTheFirstSlotAfterReadyAndNeverTwiceInOne) {
    FakeClock clock(1'000);
    VsyncPacer pacer(clock, 100.0);  // 10 ms slots from t = 1000 ns
    EXPECT_EQ(pacer.waitForScanout(1'000 + 3'000'000), 1'000 + 10'000'000);
    EXPECT_EQ(clock.nowNs(), 1'000 + 10'000'000);
    // Ready at once again: the same slot is taken, so the next one.
    EXPECT_EQ(pacer.waitForScanout(clock.nowNs()), 1'000 + 20'000'000);
    // A frame that missed two slots waits for the one after it was ready.
    EXPECT_EQ(pacer.waitForScanout(1'000 + 41'000'000), 1'000 + 50'000'000);
}

TEST(RuntimeDesigns, ParseListsAndRejectUnknownNames) {
    auto d = parseDesignList("local,qvr,fixed:12", DesignScope::Runtime);
    ASSERT_TRUE(d.ok()) << d.error();
    ASSERT_EQ(d->size(), 3u);
    EXPECT_EQ((*d)[0].design, Design::Local);
    EXPECT_EQ((*d)[1].design, Design::Qvr);
    EXPECT_EQ((*d)[2].design, Design::Fixed);
    EXPECT_DOUBLE_EQ((*d)[2].fixed_e1_deg, 12.0);
    EXPECT_EQ((*d)[2].label(), "fixed:12");
    EXPECT_FALSE(parseDesignList("local,dfr", DesignScope::Runtime).ok());
    EXPECT_FALSE(parseDesignList("", DesignScope::Runtime).ok());
}

TEST(Runtime, QvrFramesComeFromTheServerOnACleanLink) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    const HeadsetResult r = runOn(headsetConfig(Design::Ffr, (*server)->port(), "raw", 30));
    ASSERT_EQ(r.frames.size(), 30u);
    EXPECT_EQ(r.summary.frames_displayed, 30);
    EXPECT_EQ(r.stats.connects, 1u);
    int remote = 0;
    for (const FrameTelemetry& t : r.frames) {
        EXPECT_GE(t.decision_ns, t.pose_ns);
        EXPECT_GE(t.uca_end_ns, t.uca_start_ns);
        EXPECT_GE(t.display_ns, t.uca_end_ns);
        EXPECT_NEAR(t.mtp_ms, double(t.uca_end_ns - t.pose_ns) * 1e-6, 1e-6);
        if (t.remote_requested && !t.reused) {
            ++remote;
            EXPECT_GT(t.bytes, 0);
            EXPECT_GE(t.remote_done_ns, t.request_ns);
        }
    }
    EXPECT_GE(remote, 25);
    EXPECT_GE((*server)->stats().streams_sent, 100u);
}

TEST(RenderServer, StampsItsFramesOnTheInjectedClock) {
    // A clock that never moves: every stamp the server takes is its reading.
    FakeClock clock(7'000'000'000);
    RenderServerConfig sc = serverConfig("none", "raw");
    sc.clock = &clock;
    std::atomic<int> stamped{0};
    std::atomic<int> off_clock{0};
    sc.on_frame = [&](const ServerFrameStamps& s) {
        ++stamped;
        bool ok = s.queued_ns == clock.nowNs() && s.start_ns == clock.nowNs() &&
                  s.end_ns == clock.nowNs();
        for (const auto& l : s.layers)
            ok = ok && l.render_start_ns == clock.nowNs() && l.sent_ns == clock.nowNs();
        off_clock += ok ? 0 : 1;
    };
    auto server = RenderServer::start(sc, world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    runOn(headsetConfig(Design::Ffr, (*server)->port(), "raw", 10));
    (*server)->stop();
    EXPECT_GT(stamped.load(), 0);
    EXPECT_EQ(off_clock.load(), 0);
    const std::vector<ServerFrameRecord> records = (*server)->frameRecords();
    ASSERT_FALSE(records.empty());
    for (const ServerFrameRecord& r : records) {
        EXPECT_EQ(r.received_ns, 7'000'000'000);
        EXPECT_EQ(r.done_ns, 7'000'000'000);
        for (double ms : r.send_ms)
            EXPECT_EQ(ms, 0.0);
    }
    EXPECT_EQ((*server)->stats().render_ms_total, 0.0);
}

TEST(Runtime, WrongKeyIsRefusedAndTheHeadsetRendersLocally) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Qvr, (*server)->port(), "raw", 12);
    h.key = keyB();
    const HeadsetResult r = runOn(h);
    EXPECT_EQ(r.stats.connects, 0u);
    EXPECT_GE(r.stats.connect_failures, 1u);
    EXPECT_GE(r.stats.net.server_proof_failures, 1u);
    EXPECT_EQ(r.summary.frames_displayed, 12);
    for (const FrameTelemetry& t : r.frames) {
        EXPECT_TRUE(t.fallback_local);
        EXPECT_FALSE(t.remote_requested);
    }
    EXPECT_EQ((*server)->stats().frames_rendered, 0u);
    EXPECT_EQ((*server)->clients(), 0u);
}

// Writes raw bytes to the server's control port and reads until it closes (bounded).
void sendRaw(uint16_t port, const std::vector<uint8_t>& bytes) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    timeval tv{3, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ASSERT_EQ(::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL), ssize_t(bytes.size()));
    uint8_t buf[256];
    while (::recv(fd, buf, sizeof buf, 0) > 0) {
    }
    ::close(fd);
}

TEST(Runtime, MalformedTruncatedAndOversizedControlMessagesAreDroppedAndCounted) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    const uint16_t port = (*server)->port();
    // Not a qvr message at all.
    sendRaw(port, std::vector<uint8_t>(16, 0x5a));
    // A valid header that declares a payload beyond the protocol's limit.
    std::vector<uint8_t> oversized = net::encodeControl(net::ClientHello{{}, 4000});
    oversized[4] = 0x00;
    oversized[5] = 0x10;  // 4096 bytes
    oversized[6] = 0x00;
    oversized[7] = 0x00;
    sendRaw(port, oversized);
    // A ClientHello cut short: the header declares fewer bytes than the type's layout.
    std::vector<uint8_t> truncated = net::encodeControl(net::ClientHello{{}, 4000});
    truncated[4] = 10;
    truncated.resize(net::kControlHeaderBytes + 10);
    sendRaw(port, truncated);
    // The server keeps serving a real headset afterwards.
    const HeadsetResult r = runOn(headsetConfig(Design::Ffr, port, "raw", 20));
    EXPECT_EQ(r.stats.connects, 1u);
    EXPECT_EQ(r.summary.frames_displayed, 20);
    EXPECT_LT(r.summary.frames_reused, 10);
    const net::ServerStats st = (*server)->stats().net;
    EXPECT_GE(st.control_drops[net::WireError::kBadMagic], 1u);
    EXPECT_GE(st.control_drops[net::WireError::kOversized], 1u);
    EXPECT_GE(st.control_drops[net::WireError::kTruncated], 1u);
    EXPECT_EQ(st.clients_accepted, 1u);
}

TEST(Runtime, FivePercentPacketLossKeepsFramesComingWithReusedFramesCounted) {
    auto server = RenderServer::start(serverConfig("wifi,loss=0.05,seed=3", "x264"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    const int frames = 90;
    const HeadsetResult r = runOn(headsetConfig(Design::Ffr, (*server)->port(), "x264", frames));
    EXPECT_EQ(r.summary.frames_displayed, frames);
    // Reused frames are counted (with FEC and in-order NACK recovery there may be none).
    int reused = 0;
    for (const FrameTelemetry& t : r.frames)
        reused += t.reused ? 1 : 0;
    EXPECT_EQ(r.summary.frames_reused, reused);
    // Packets were lost, and repaired: by FEC parity, NACKed retransmission or (when a frame
    // is given up) key frames — the two first make no key-frame request at all.
    const net::AssemblerStats& as = r.stats.net.assembler;
    EXPECT_GT(as.seq_gap_packets, 0u);
    EXPECT_GT(as.fec_recoveries + as.packets_recovered + r.stats.key_frame_requests +
                  r.stats.net.key_frame_requests_sent,
              0u);
    // Fresh remote frames keep arriving through the last third.
    int fresh_late = 0;
    for (int i = 2 * frames / 3; i < frames; ++i)
        fresh_late += r.frames[static_cast<size_t>(i)].reused ? 0 : 1;
    EXPECT_GT(fresh_late, 5);
}

TEST(Runtime, ALongSessionHoldsOnlyItsNewestFramesAndStreamsTheRestInOrder) {
    // qvr client's mode: keep_frames bounds the telemetry in memory; every frame still reaches
    // the sink once, in order, and the summary is the whole session's (over lossy media, so
    // late streams of frames already shown do arrive while older frames are retired).
    auto server = RenderServer::start(serverConfig("wifi,loss=0.05,seed=5", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Qvr, (*server)->port(), "raw", 200);
    h.keep_frames = 10;  // held: at least 64
    h.warmup_frames = 10;
    std::vector<FrameTelemetry> sunk;
    h.frame_sink = [&sunk](const FrameTelemetry& t) { sunk.push_back(t); };
    const HeadsetResult r = runOn(h);
    ASSERT_EQ(sunk.size(), 200u);
    for (size_t i = 0; i < sunk.size(); ++i)
        ASSERT_EQ(sunk[i].frame, static_cast<int64_t>(i));
    ASSERT_EQ(r.frames.size(), 64u);
    EXPECT_EQ(r.frames.front().frame, 200 - 64);
    EXPECT_EQ(r.frames.back().bytes, sunk.back().bytes);
    const DesignSummary whole = summarizeRun("qvr", sunk, 10);
    EXPECT_EQ(r.summary.frames, 190);
    EXPECT_EQ(r.summary.frames_displayed, whole.frames_displayed);
    EXPECT_EQ(r.summary.frames_reused, whole.frames_reused);
    EXPECT_DOUBLE_EQ(r.summary.mtp_ms_p99, whole.mtp_ms_p99);
    EXPECT_DOUBLE_EQ(r.summary.bytes_per_frame_mean, whole.bytes_per_frame_mean);
    EXPECT_GT(whole.bytes_per_frame_mean, 0.0);
}

TEST(Runtime, AStalledServerDoesNotStallTheDisplay) {
    // The server's render thread stops for 1.5 s after its 20th frame (as under SIGSTOP). The
    // headset keeps scanning out at its own rate, re-warping the newest layers it has, and shows
    // fresh frames again once the server resumes. (Before: every frame of the stall waited the
    // whole 250 ms wait limit, a 4 Hz display.)
#if defined(__SANITIZE_THREAD__)
    // Under ThreadSanitizer every frame of this build takes longer than the 150 ms gap the test
    // counts (222 of 240 were long gaps): it measures the display's cadence, which TSan's
    // slowdown erases. It runs in the default and asan suites.
    GTEST_SKIP() << "display cadence is not measurable under ThreadSanitizer";
#endif
    // The stall lasts 1.5 s and at least 16 of the headset's frames, so that it spans as many
    // frames on a slow build (ASan beside a compile: ~120 ms a frame) as on a fast one; 30 s at
    // most, so a display that stopped fails the test instead of hanging it.
    RenderServerConfig sc = serverConfig("none", "raw");
    std::atomic<int> served{0};
    std::atomic<int64_t> headset_frame{0};
    sc.on_frame = [&served, &headset_frame](const ServerFrameStamps&) {
        if (++served != 20)
            return;
        const auto t0 = std::chrono::steady_clock::now();
        const int64_t until = headset_frame.load() + 16;
        for (;;) {
            const auto spent = std::chrono::steady_clock::now() - t0;
            if (spent > std::chrono::seconds(30) ||
                (spent >= std::chrono::milliseconds(1500) && headset_frame.load() >= until))
                break;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
    };
    auto server = RenderServer::start(sc, world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Ffr, (*server)->port(), "raw", 240);
    h.before_frame = [&headset_frame](int64_t f) { headset_frame.store(f); };
    const HeadsetResult r = runOn(h);
    ASSERT_EQ(r.frames.size(), 240u);
    // The first frame into the stall waits the limit (nothing yet says the server stopped);
    // after it the display keeps its rate (before: six gaps in a row each 250 ms longer than
    // the display's usual one). A gap is long when it exceeds the run's median gap by 200 ms:
    // on an ASan build a frame alone takes ~120 ms, so a fixed 150 ms counted ordinary frames
    // (8 in an idle CI run). Two more long gaps are allowed for a loaded machine's scheduling.
    std::vector<int64_t> gaps;
    for (size_t i = 1; i < r.frames.size(); ++i)
        gaps.push_back(r.frames[i].display_ns - r.frames[i - 1].display_ns);
    std::vector<int64_t> sorted = gaps;
    std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
    const int64_t median_gap = sorted[sorted.size() / 2];
    int long_gaps = 0;
    for (int64_t g : gaps)
        long_gaps += g > median_gap + 200'000'000;
    EXPECT_LE(long_gaps, 3) << "median gap " << median_gap / 1'000'000 << " ms";
    // ~135 at 90 Hz; 27 on an ASan build, 13 (3 long gaps) on an ASan build with a calibration
    // and a compile beside it on two cores when the stall was 1.5 s alone; 6 before the fix,
    // each frame waiting the limit.
    EXPECT_GT(r.stats.silent_server_frames, 8u);
    EXPECT_GT(r.summary.frames_reused, 8);
    // Fresh frames again after the stall: the last 40 frames come from the server.
    int fresh_tail = 0;
    for (size_t i = 200; i < 240; ++i)
        fresh_tail += r.frames[i].reused ? 0 : 1;
    EXPECT_GT(fresh_tail, 30);
}

TEST(PendingFrames, TheOldestGoFirstUntilBothBoundsHoldAndTheNewestAlwaysStays) {
    const std::vector<size_t> none;
    EXPECT_EQ(pendingFramesToDrop(none, 4, 100), 0u);
    const std::vector<size_t> five(5, 10);  // 50 bytes in all
    EXPECT_EQ(pendingFramesToDrop(five, 5, 50), 0u);
    EXPECT_EQ(pendingFramesToDrop(five, 4, 50), 1u);  // the count
    EXPECT_EQ(pendingFramesToDrop(five, 5, 35), 2u);  // the bytes: 30 left
    EXPECT_EQ(pendingFramesToDrop(five, 0, 0), 4u);   // the newest stays
    // Bytes drop by the oldest frames' own sizes: a large old frame frees room at once.
    const std::vector<size_t> mixed = {40, 1, 1, 1};
    EXPECT_EQ(pendingFramesToDrop(mixed, 64, 10), 1u);
    // The bounds the headset uses hold 64 frames of qvr's fovea but not of a big one.
    const size_t fovea_5deg = size_t(2) * 224 * 224 * 4;   // ~0.4 MB
    const size_t fovea_20deg = size_t(2) * 784 * 784 * 4;  // ~4.9 MB
    EXPECT_EQ(pendingFramesToDrop(std::vector<size_t>(64, fovea_5deg), kMaxPendingFrames,
                                  kMaxPendingImageBytes),
              0u);
    EXPECT_EQ(pendingFramesToDrop(std::vector<size_t>(65, fovea_5deg), kMaxPendingFrames,
                                  kMaxPendingImageBytes),
              1u);
    EXPECT_EQ(pendingFramesToDrop(std::vector<size_t>(64, fovea_20deg), kMaxPendingFrames,
                                  kMaxPendingImageBytes),
              64u - kMaxPendingImageBytes / fovea_20deg);
}

TEST(Runtime, AServerSlowerThanTheWaitLimitStillGetsItsFramesShown) {
    // Each remote frame takes the server 2 x 150 ms (two whole-frame layers) against a 20 ms
    // wait limit: the headset re-warps at its own pace, ~13 frames for each of the server's.
    // The frame the server is rendering must keep its pending entry until its layers come:
    // they are the newest the headset will have. Before, the headset held only its newest 8
    // requests, so every frame the server finished had already lost its entry and was
    // discarded, and nothing from the server was ever shown (as in a validation run: room,
    // lte, remote, the server at 661 ms a frame against the 250 ms limit, 40 frames).
    RenderServerConfig sc = serverConfig("none", "raw");
    sc.renderer = []() -> Expected<std::unique_ptr<Renderer>> {
        return std::unique_ptr<Renderer>(std::make_unique<SlowRenderer>(150ms));
    };
    auto server = RenderServer::start(sc, world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Remote, (*server)->port(), "raw", 200);
    h.remote_timeout_ms = 20.0;
    const HeadsetResult r = runOn(h);
    ASSERT_EQ(r.frames.size(), 200u);
    std::vector<int64_t> shown;
    for (const FrameTelemetry& t : r.frames)
        if (t.shown_frame >= 0 && (shown.empty() || shown.back() != t.shown_frame))
            shown.push_back(t.shown_frame);
    // 200 frames of >= 20 ms are >= 4 s: ~13 server frames; at least 6 shown.
    EXPECT_GE(shown.size(), 6u) << r.stats.streams_discarded << " streams discarded";
    EXPECT_TRUE(std::is_sorted(shown.begin(), shown.end()));
    // Each shown frame is one the server rendered while the headset moved on: all late.
    EXPECT_GT(r.summary.frames_reused, 150);
}

TEST(Runtime, ALateFramesStreamsCountAsItsBytesAfterItWasShown) {
    // A 40 Mbit/s link carries a frame's four raw streams (~0.5 MB) in ~100 ms, and the headset
    // waits 30 ms for them: every frame is shown re-warped (reused) and its streams land two or
    // more frames later, after it left the pending list. They crossed the link for it, so they
    // are its bytes. Before, bytes counted only while the frame was pending, so these frames
    // had none.
    RenderServerConfig sc = serverConfig("rate:40", "raw");
    auto server = RenderServer::start(sc, world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Ffr, (*server)->port(), "raw", 60);
    h.pipeline_depth = 1;
    h.remote_timeout_ms = 30.0;
    const HeadsetResult r = runOn(h);
    ASSERT_EQ(r.frames.size(), 60u);
    int late_with_bytes = 0;
    int64_t bytes = 0;
    for (const FrameTelemetry& t : r.frames) {
        late_with_bytes += t.reused && t.bytes > 0 ? 1 : 0;
        bytes += t.bytes;
    }
    EXPECT_GE(late_with_bytes, 5) << bytes << " bytes counted in all";
}

TEST(Runtime, TheServerSaysHowLongItTookAndTheHeadsetSeesIt) {
    // Each layer takes the server at least 15 ms to render, four layers a frame: each frame's
    // headers say at least 60 ms from when the server started on it, and no more than the
    // frame's T_remote, which also holds the transmission (give or take the few ms between the
    // request leaving and the headset stamping it). LIWC learns the server's part from this, not
    // from T_remote less an estimate of the link's (docs/LIWC.md).
    RenderServerConfig sc = serverConfig("none", "raw");
    sc.renderer = []() -> Expected<std::unique_ptr<Renderer>> {
        return std::unique_ptr<Renderer>(std::make_unique<SlowRenderer>(15ms));
    };
    auto server = RenderServer::start(sc, world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Ffr, (*server)->port(), "raw", 30);
    h.pipeline_depth = 1;
    const HeadsetResult r = runOn(h);
    int said = 0;
    for (const FrameTelemetry& t : r.frames) {
        if (t.remote_done_ns < 0 || t.reused)
            continue;
        ++said;
        EXPECT_GE(t.server_ms, 4 * 15.0) << t.frame;
        EXPECT_LE(t.server_ms, t.t_remote_ms + 5.0) << t.frame;
    }
    EXPECT_GE(said, 10);
}

TEST(Runtime, ALinkSlowerThanTheFramesQueuesNoMoreThanTheRequestWindow) {
    // A 10 Mbit/s link carries a frame's raw periphery (~400 KB) in ~300 ms while the headset asks
    // at its own pace, every ~11-30 ms. Asked for every frame, the peripheries queued in the link's
    // buffer and each came later than the one before, seconds behind by the end. The headset
    // keeps at most RequestWindow::window(depth) requests outstanding and shows the frames it
    // did not ask for with the newest periphery at once: a periphery's delay stays within the
    // window's transfers.
    RenderServerConfig sc = serverConfig("rate:10", "raw");
    auto server = RenderServer::start(sc, world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(Design::Ffr, (*server)->port(), "raw", 150);
    const HeadsetResult r = runOn(h);
    ASSERT_EQ(r.frames.size(), 150u);
    EXPECT_GT(r.stats.requests_withheld, 0u);
    std::vector<double> delays_ms;
    double bytes = 0.0;
    for (const FrameTelemetry& t : r.frames) {
        if (t.remote_requested && t.remote_done_ns > 0) {
            delays_ms.push_back(double(t.remote_done_ns - t.request_ns) * 1e-6);
            bytes += double(t.bytes);
        }
    }
    ASSERT_GE(delays_ms.size(), 5u)
        << r.stats.streams_received << " streams, " << r.stats.requests_withheld << " withheld, "
        << r.stats.streams_lost << " lost";
    const double transfer_ms = bytes / double(delays_ms.size()) * 8.0 / 10e6 * 1000.0;
    const double window = double(RequestWindow::window(2));
    const double worst = *std::max_element(delays_ms.begin() + 2, delays_ms.end());
    EXPECT_LT(worst, (window + 1.0) * transfer_ms + 100.0)
        << "a transfer " << transfer_ms << " ms, " << delays_ms.size() << " arrived";
}

TEST(Runtime, KillingTheServerLeavesTheHeadsetDisplayingAndItReconnects) {
    auto first = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(first.ok()) << first.error();
    std::unique_ptr<RenderServer> server = std::move(*first);
    const uint16_t port = server->port();
    const int frames = 150;
    // ffr, so every frame asks for remote layers: with the null renderer's ~0.1 ms fovea, LIWC
    // rightly grows the fovea over the whole field after the reconnect and asks for nothing.
    HeadsetConfig h = headsetConfig(Design::Ffr, port, "raw", frames);
    bool restarted = false;
    h.before_frame = [&](int64_t i) {
        if (i == 30)
            server.reset();  // the server process dies
        if (i == 60) {
            RenderServerConfig c = serverConfig("none", "raw");
            c.net.port = port;
            auto again = RenderServer::start(c, world().scene);
            restarted = again.ok();
            if (again)
                server = std::move(*again);
        }
    };
    const HeadsetResult r = runOn(h);
    ASSERT_TRUE(restarted);
    EXPECT_EQ(r.summary.frames_displayed, frames);
    EXPECT_GE(r.stats.connects, 2u);
    EXPECT_GE(r.stats.disconnects, 1u);
    int fallback_while_down = 0, remote_after = 0;
    for (const FrameTelemetry& t : r.frames) {
        if (t.frame >= 31 && t.frame < 60)
            fallback_while_down += t.fallback_local ? 1 : 0;
        if (t.frame >= 100)
            remote_after += (t.remote_requested && !t.reused) ? 1 : 0;
    }
    EXPECT_GE(fallback_while_down, 20);
    EXPECT_GE(remote_after, 40);
}

double meanE1(const HeadsetResult& r, size_t from) {
    double s = 0;
    for (size_t i = from; i < r.frames.size(); ++i)
        s += r.frames[i].e1_deg;
    return s / double(r.frames.size() - from);
}

TEST(Runtime, ASlowLinkChoosesALargerMeanFoveaThan5g) {
    if (!glAvailable())
        GTEST_SKIP() << "no EGL/OpenGL 4.5 here";
    // The raw codec makes the periphery heavy enough (4 bytes a pixel) that the link decides
    // T_remote: LIWC must move work to the headset on the slower link. The server renders with
    // the null renderer: in one process a GL server would share llvmpipe's rasterizer with the
    // headset (docs/RUNTIME.md), and LIWC, which learns the server's render time, would then
    // push both runs towards an all-local fovea where the link no longer matters.
    auto run = [](const std::string& link) {
        auto server = RenderServer::start(serverConfig(link, "raw", false), world().scene);
        EXPECT_TRUE(server.ok());
        if (!server)
            return 0.0;
        const HeadsetResult r =
            runOn(headsetConfig(Design::Qvr, (*server)->port(), "raw", 90, true));
        EXPECT_EQ(r.summary.frames_displayed, 90);
        return meanE1(r, 30);
    };
    // 5 Mbit/s: at this small profile even the lte preset (100 Mbit/s) carries the raw periphery
    // faster than the headset renders, and LIWC's frame-period objective then rightly keeps the
    // fovea at its floor on both links; the link must be the bottleneck for e1 to grow.
    const double e1_lte = run("rate:5");
    const double e1_5g = run("5g");
    RecordProperty("e1_lte_deg", std::to_string(e1_lte));
    RecordProperty("e1_5g_deg", std::to_string(e1_5g));
    EXPECT_GT(e1_lte, e1_5g + 1.0) << "5 Mbit/s " << e1_lte << " vs 5g " << e1_5g;
}

// ---- media-level faults -------------------------------------------------------------------
// Neither side's media port is reachable through the public API: RenderServer does not expose
// its UDP port, the headset's is private to net::Client, and the headset's socket is connected to
// the server's media port, so the kernel drops datagrams from anywhere else. A test that holds
// the pre-shared key can still stand in the middle: it relays the control channel, rewrites the
// media ports in ClientHello and Welcome (re-signing ClientAuth, whose proof covers the port), and
// forwards the server's datagrams to the headset from its own UDP socket — the one source the
// headset then accepts — slipping malformed ones in between.

int loopbackSocket(int type) {
    const int fd = ::socket(AF_INET, type | SOCK_CLOEXEC, 0);
    if (fd < 0)
        return -1;
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}

uint16_t localPort(int fd) {
    sockaddr_in a{};
    socklen_t n = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
    return ntohs(a.sin_port);
}

bool readExact(int fd, uint8_t* p, size_t n) {
    while (n > 0) {
        const ssize_t r = ::recv(fd, p, n, 0);
        if (r <= 0)
            return false;
        p += r;
        n -= static_cast<size_t>(r);
    }
    return true;
}

bool writeAll(int fd, const std::vector<uint8_t>& bytes) {
    size_t off = 0;
    while (off < bytes.size()) {
        const ssize_t w = ::send(fd, bytes.data() + off, bytes.size() - off, MSG_NOSIGNAL);
        if (w <= 0)
            return false;
        off += static_cast<size_t>(w);
    }
    return true;
}

// One control message, raw (header + payload) and decoded; a sealed one stays raw (`sealed`).
bool readControl(int fd, std::vector<uint8_t>& raw, net::ControlMessage& message, bool& sealed) {
    raw.assign(net::kControlHeaderBytes, 0);
    if (!readExact(fd, raw.data(), raw.size()))
        return false;
    net::ControlHeader h;
    if (net::decodeControlHeader(raw, h) != net::WireError::kNone)
        return false;
    raw.resize(net::kControlHeaderBytes + h.payload_bytes);
    if (!readExact(fd, raw.data() + net::kControlHeaderBytes, h.payload_bytes))
        return false;
    sealed = h.type == net::ControlType::kSealed;
    return sealed || net::decodeControl(raw, message) == net::WireError::kNone;
}

class MediaTamperingProxy {
public:
    MediaTamperingProxy(uint16_t server_port, net::PresharedKey key, int last_frame_to_tamper)
        : m_server_port(server_port), m_key(key), m_last_frame(last_frame_to_tamper) {
        m_listen = loopbackSocket(SOCK_STREAM);
        m_from_server = loopbackSocket(SOCK_DGRAM);
        m_to_headset = loopbackSocket(SOCK_DGRAM);
        QVR_CHECK(m_listen >= 0 && m_from_server >= 0 && m_to_headset >= 0);
        QVR_CHECK(::listen(m_listen, 1) == 0);
        timeval tv{0, 50'000};
        ::setsockopt(m_from_server, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        // As deep as the headset's own socket (net::Client asks for 4 MB): a frame's burst must
        // not overflow the relay and pass for a fault of the headset's.
        const int buffer_bytes = 4 << 20;
        ::setsockopt(m_from_server, SOL_SOCKET, SO_RCVBUF, &buffer_bytes, sizeof buffer_bytes);
        ::setsockopt(m_to_headset, SOL_SOCKET, SO_SNDBUF, &buffer_bytes, sizeof buffer_bytes);
        m_control = std::thread([this] { relayControl(); });
        m_media = std::thread([this] { relayMedia(); });
    }
    ~MediaTamperingProxy() {
        m_stop = true;
        for (int fd : {m_headset.load(), m_server.load()})
            if (fd >= 0)
                ::shutdown(fd, SHUT_RDWR);
        m_control.join();
        m_media.join();
        for (int fd : {m_listen, m_from_server, m_to_headset, m_headset.load(), m_server.load()})
            if (fd >= 0)
                ::close(fd);
    }
    uint16_t port() const { return localPort(m_listen); }
    // The malformed datagrams sent, by the reason the headset should drop each for.
    net::DropCounters injected() const {
        std::lock_guard lock(m_mutex);
        return m_injected;
    }
    uint64_t forwarded() const { return m_forwarded; }

private:
    void relayControl() {
        pollfd p{m_listen, POLLIN, 0};
        while (!m_stop && ::poll(&p, 1, 50) == 0) {
        }
        if (m_stop)
            return;
        const int headset = ::accept4(m_listen, nullptr, nullptr, SOCK_CLOEXEC);
        const int server = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(m_server_port);
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (headset < 0 || server < 0 ||
            ::connect(server, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
            ADD_FAILURE() << "proxy: cannot relay to the server";
            return;
        }
        m_headset = headset;
        m_server = server;
        std::thread down([this] { relay(m_server, m_headset); });
        relay(m_headset, m_server);
        ::shutdown(m_server, SHUT_RDWR);
        down.join();
    }

    // Forwards control messages from `from` to `to`, rewriting the handshake's media ports (the
    // proxy holds the key, so it can open and re-seal the server's Welcome).
    void relay(int from, int to) {
        std::vector<uint8_t> raw;
        net::ControlMessage m;
        bool sealed = false;
        uint64_t next_counter = 0;  // of the server's sealed messages
        while (readControl(from, raw, m, sealed)) {
            std::unique_lock lock(m_mutex);
            if (sealed) {
                if (from == m_server) {
                    const net::ControlKey key =
                        net::sessionKeys(m_key, m_client_nonce, m_server_nonce, m_session)
                            .server_to_client;
                    const uint64_t counter = next_counter;
                    if (net::openControl(raw, key, next_counter, m) == net::WireError::kNone) {
                        if (auto* welcome = std::get_if<net::Welcome>(&m)) {
                            welcome->media_port = localPort(m_to_headset);
                            raw = net::sealControl(*welcome, key, counter);
                        }
                    }
                }
            } else if (auto* hello = std::get_if<net::ClientHello>(&m)) {
                m_client_nonce = hello->client_nonce;
                m_headset_media_port = hello->media_port;
                hello->media_port = localPort(m_from_server);
                raw = net::encodeControl(*hello);
            } else if (const auto* ch = std::get_if<net::ServerChallenge>(&m)) {
                m_server_nonce = ch->server_nonce;
                m_session = ch->session_id;
            } else if (std::holds_alternative<net::ClientAuth>(m)) {
                raw = net::encodeControl(net::ClientAuth{net::clientProof(
                    m_key, m_client_nonce, m_server_nonce, m_session, localPort(m_from_server))});
            } else if (auto* welcome = std::get_if<net::Welcome>(&m)) {
                welcome->media_port = localPort(m_to_headset);
                raw = net::encodeControl(*welcome);
            }
            lock.unlock();
            if (!writeAll(to, raw))
                break;
        }
        ::shutdown(to, SHUT_WR);
    }

    void relayMedia() {
        std::vector<uint8_t> datagram(65536);
        uint32_t tampered_up_to = 0;
        bool tampered_any = false;
        while (!m_stop) {
            const ssize_t n = ::recv(m_from_server, datagram.data(), datagram.size(), 0);
            if (n <= 0)
                continue;
            const std::vector<uint8_t> packet(datagram.begin(), datagram.begin() + n);
            uint16_t port = 0;
            uint64_t session = 0;
            net::MediaKey key{};
            {
                std::lock_guard lock(m_mutex);
                port = m_headset_media_port;
                session = m_session;
                // Holding the key, the proxy can open the media and seal what it injects.
                key = net::mediaKey(m_key, m_client_nonce, m_server_nonce, m_session);
            }
            std::vector<uint8_t> plain = packet;
            net::MediaPacketView view;
            const bool valid =
                net::openMediaPacket(plain, key) == net::WireError::kNone &&
                net::decodeMediaPacket(std::span(plain).first(plain.size() - net::kMediaTagBytes),
                                       view) == net::WireError::kNone;
            plain.resize(plain.size() - std::min(plain.size(), net::kMediaTagBytes));
            // A burst of every kind of malformed datagram ahead of the first packet of every
            // third frame, until the last frames, so the headset has read them all by its end.
            const uint32_t frame = valid ? view.header.frame_id : 0;
            if (valid && frame % 3 == 0 && int(frame) <= m_last_frame &&
                (!tampered_any || frame > tampered_up_to)) {
                tampered_any = true;
                tampered_up_to = frame;
                injectBurst(port, session, key, plain, frame);
                sendTo(port, packet);
                ++m_forwarded;
                // The authentic datagram again: a replay.
                sendTo(port, packet);
                std::lock_guard lock(m_mutex);
                m_injected.count(net::WireError::kReplayed);
                continue;
            }
            sendTo(port, packet);
            ++m_forwarded;
        }
    }

    void sendTo(uint16_t port, const std::vector<uint8_t>& d) {
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(port);
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        ::sendto(m_to_headset, d.data(), d.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
    }

    // `real` is an opened (plain) datagram of the session; what is injected is sealed with the
    // session's key wherever the malformation lies behind the tag, so it is counted by reason.
    void injectBurst(uint16_t port, uint64_t session, const net::MediaKey& key,
                     const std::vector<uint8_t>& real, uint32_t frame) {
        using net::WireError;
        std::vector<std::pair<WireError, std::vector<uint8_t>>> bad;
        auto sealed = [&](std::vector<uint8_t> d) {
            net::sealMediaPacket(d, key);
            return d;
        };
        auto encoded = [&](net::MediaHeader h, size_t payload_bytes) {
            std::vector<uint8_t> out;
            net::encodeMediaPacket(h, std::vector<uint8_t>(payload_bytes, 0x77), out);
            return out;
        };
        net::MediaHeader h;
        h.session_id = session;
        h.frame_id = frame;
        h.stream_id = 0;
        h.packet_count = 1;
        h.payload_bytes = 100;
        h.frame_bytes = 100;
        // Garbage, too short for a header, too long for any datagram.
        std::vector<uint8_t> garbage(64);
        for (size_t i = 0; i < garbage.size(); ++i)
            garbage[i] = static_cast<uint8_t>(0xA5 ^ (i * 37));
        bad.emplace_back(WireError::kBadMagic, garbage);
        bad.emplace_back(WireError::kTruncated, std::vector<uint8_t>(7, 0x51));
        bad.emplace_back(WireError::kOversized,
                         std::vector<uint8_t>(net::kMaxDatagramBytes + 500, 0));
        // A real packet of this session cut short of its declared payload.
        bad.emplace_back(WireError::kTruncated,
                         sealed(std::vector<uint8_t>(real.begin(), real.end() - 1)));
        // A header declaring a full 1200-byte chunk with 100 bytes behind it.
        {
            net::MediaHeader full = h;
            full.packet_count = 2;
            full.payload_bytes = net::kMediaChunkBytes;
            full.frame_bytes = 2 * net::kMediaChunkBytes;
            auto d = encoded(full, net::kMediaChunkBytes);
            d.resize(net::kMediaHeaderBytes + 100);
            bad.emplace_back(WireError::kTruncated, sealed(d));
        }
        // More bytes than declared.
        {
            auto d = encoded(h, 100);
            d.insert(d.end(), 50, 0x33);
            bad.emplace_back(WireError::kTrailingBytes, sealed(d));
        }
        // A frame size beyond the protocol's limit.
        {
            net::MediaHeader big = h;
            big.frame_bytes = net::kMaxStreamFrameBytes + 1;
            bad.emplace_back(WireError::kOversized, sealed(encoded(big, 100)));
        }
        // Packet 5 of a frame of one packet.
        {
            net::MediaHeader past = h;
            past.packet_index = 5;
            bad.emplace_back(WireError::kBadField, sealed(encoded(past, 100)));
        }
        // Another protocol version.
        {
            auto d = real;
            d[2] = static_cast<uint8_t>(d[2] + 1);
            bad.emplace_back(WireError::kWrongVersion, sealed(d));
        }
        // Forged: the plain datagram (no tag), and a sealed one with a payload bit flipped.
        bad.emplace_back(real.size() < net::kMediaHeaderBytes + net::kMediaTagBytes
                             ? WireError::kTruncated
                             : WireError::kBadMac,
                         real);
        {
            auto d = sealed(real);
            d[net::kMediaHeaderBytes + 3] ^= 0x04;
            bad.emplace_back(WireError::kBadMac, d);
        }
        // A well-formed packet of another session.
        {
            net::MediaHeader other = h;
            other.session_id = session + 1;
            bad.emplace_back(WireError::kWrongSession, sealed(encoded(other, 100)));
        }
        for (const auto& [why, d] : bad) {
            sendTo(port, d);
            std::lock_guard lock(m_mutex);
            m_injected.count(why);
        }
    }

    const uint16_t m_server_port;
    const net::PresharedKey m_key;
    const int m_last_frame;
    int m_listen = -1;
    int m_from_server = -1;  // the server sends the media here
    int m_to_headset = -1;   // and the headset accepts it only from here
    std::atomic<int> m_headset{-1};
    std::atomic<int> m_server{-1};
    std::atomic<bool> m_stop{false};
    std::atomic<uint64_t> m_forwarded{0};
    mutable std::mutex m_mutex;
    net::Nonce m_client_nonce{};
    net::Nonce m_server_nonce{};
    uint64_t m_session = 0;
    uint16_t m_headset_media_port = 0;
    net::DropCounters m_injected;
    std::thread m_control;
    std::thread m_media;
};

TEST(Runtime, MalformedMediaDatagramsAreDroppedByReasonWhileFramesKeepComing) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    const int frames = 60;
    net::DropCounters injected;
    HeadsetResult r;
    {
        MediaTamperingProxy proxy((*server)->port(), keyA(), frames - 15);
        // ffr: a fixed fovea, so every frame asks for remote layers (with the null renderer
        // LIWC may grow the fovea over the whole field and stop asking).
        r = runOn(headsetConfig(Design::Ffr, proxy.port(), "raw", frames));
        EXPECT_GT(proxy.forwarded(), 100u);
        injected = proxy.injected();
    }
    // The run went through the proxy, and the proxy did tamper.
    EXPECT_EQ(r.stats.connects, 1u);
    EXPECT_EQ(r.stats.disconnects, 0u);
    ASSERT_GE(injected.total(), 10u * 10u) << "too few frames were tampered with";
    // Every malformed datagram was dropped and counted under its reason; nothing else was.
    const net::DropCounters& drops = r.stats.net.media_drops;
    for (int e = 1; e < net::kWireErrorCount; ++e) {
        const auto why = static_cast<net::WireError>(e);
        if (why == net::WireError::kReplayed)
            continue;
        EXPECT_EQ(drops[why], injected[why]) << net::wireErrorName(why);
    }
    // A second copy is a second copy: besides the proxy's replays, a retransmission that raced
    // its delayed original (the proxy holds packets while it injects) is dropped the same way,
    // so at most one per packet the headset NACKed.
    EXPECT_GE(drops[net::WireError::kReplayed], injected[net::WireError::kReplayed]);
    EXPECT_LE(drops[net::WireError::kReplayed],
              injected[net::WireError::kReplayed] + r.stats.net.assembler.packets_nacked);
    EXPECT_GT(drops[net::WireError::kWrongSession], 0u);
    EXPECT_GT(drops[net::WireError::kTrailingBytes], 0u);
    EXPECT_GT(drops[net::WireError::kBadMac], 0u);    // forged and bit-flipped
    EXPECT_GT(drops[net::WireError::kReplayed], 0u);  // authentic, sent twice
    EXPECT_EQ(drops[net::WireError::kTruncated], 3 * drops[net::WireError::kBadMagic]);
    // Frames kept coming from the server: every frame displayed, nearly all of them fresh.
    EXPECT_EQ(r.summary.frames_displayed, frames);
    EXPECT_LT(r.summary.frames_reused, frames / 10);
    EXPECT_EQ(r.stats.decode_failures, 0u);
    EXPECT_EQ(r.stats.streams_lost, 0u);
    int fresh = 0;
    for (const FrameTelemetry& t : r.frames)
        fresh += (t.remote_requested && !t.reused && t.bytes > 0) ? 1 : 0;
    EXPECT_GE(fresh, frames - frames / 10);
}

// ---- frames in flight (HeadsetConfig::pipeline_depth) ------------------------------------

// Pairs (n, n + 1) that both requested remote layers, and how many of them had n + 1's request
// sent before n's UCA started.
std::pair<int, int> requestsAheadOfUca(const HeadsetResult& r) {
    int pairs = 0, ahead = 0;
    for (size_t n = 0; n + 1 < r.frames.size(); ++n) {
        const FrameTelemetry& a = r.frames[n];
        const FrameTelemetry& b = r.frames[n + 1];
        if (!a.remote_requested || !b.remote_requested || a.uca_start_ns < 0)
            continue;
        ++pairs;
        ahead += b.request_ns < a.uca_start_ns ? 1 : 0;
    }
    return {pairs, ahead};
}

TEST(Runtime, TwoFramesInFlightRequestTheNextFrameBeforeComposingThisOne) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    const int frames = 40;
    for (int depth : {2, 1}) {
        // ffr: every frame requests remote layers (LIWC with the null renderer may grow the
        // fovea over the whole field, and then a frame asks for nothing).
        HeadsetConfig h = headsetConfig(Design::Ffr, (*server)->port(), "raw", frames);
        h.pipeline_depth = depth;
        const HeadsetResult r = runOn(h);
        ASSERT_EQ(r.frames.size(), size_t(frames));
        EXPECT_EQ(r.summary.frames_displayed, frames);
        // Telemetry is in frame order whatever the depth.
        for (size_t n = 0; n < r.frames.size(); ++n)
            EXPECT_EQ(r.frames[n].frame, int64_t(n));
        const auto [pairs, ahead] = requestsAheadOfUca(r);
        EXPECT_GE(pairs, frames - 5) << "depth " << depth;
        if (depth == 2) {
            EXPECT_GE(ahead, pairs * 9 / 10) << ahead << " of " << pairs;
        } else {
            EXPECT_EQ(ahead, 0) << pairs;
            // One frame at a time: the next pose is sampled after this frame's scan-out.
            for (size_t n = 0; n + 1 < r.frames.size(); ++n)
                EXPECT_GE(r.frames[n + 1].pose_ns, r.frames[n].uca_end_ns) << "frame " << n;
        }
    }
}

TEST(Runtime, LocalDesignIgnoresThePipelineDepth) {
    // Nothing remote to overlap with: frame n + 1's pose is sampled after n is displayed.
    const int frames = 30;
    HeadsetConfig h = headsetConfig(Design::Local, 0, "raw", frames);
    h.pipeline_depth = 2;
    const HeadsetResult r = runOn(h);
    ASSERT_EQ(r.frames.size(), size_t(frames));
    EXPECT_EQ(r.summary.frames_displayed, frames);
    for (size_t n = 0; n + 1 < r.frames.size(); ++n) {
        ASSERT_GE(r.frames[n].display_ns, 0);
        EXPECT_FALSE(r.frames[n].remote_requested);
        EXPECT_GE(r.frames[n + 1].pose_ns, r.frames[n].uca_end_ns) << "frame " << n;
    }
}

}  // namespace
}  // namespace qvr::runtime
