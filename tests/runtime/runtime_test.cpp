// The runtime end to end on 127.0.0.1 (issue 6): a render server and a headset through net's
// transport and link emulator. Small profiles and few frames keep each test to seconds.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <numeric>
#include <thread>

#include "qvr/net/protocol.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/pacing.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/session.h"
#include "qvr/scene/scene_loader.h"

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
    c.net.link = net::parseLinkSpec(link).value();
    c.profile = world().profile;
    c.codec.backend = codec;
    c.renderer = gl ? glRendererFactory() : nullRendererFactory();
    return c;
}

HeadsetConfig headsetConfig(RuntimeDesign design, uint16_t port, const std::string& codec,
                            int frames, bool gl = false) {
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
    FakePacingClock clock(1'000);
    VsyncPacer pacer(clock, 100.0);  // 10 ms slots from t = 1000 ns
    EXPECT_EQ(pacer.waitForScanout(1'000 + 3'000'000), 1'000 + 10'000'000);
    EXPECT_EQ(clock.nowNs(), 1'000 + 10'000'000);
    // Ready at once again: the same slot is taken, so the next one.
    EXPECT_EQ(pacer.waitForScanout(clock.nowNs()), 1'000 + 20'000'000);
    // A frame that missed two slots waits for the one after it was ready.
    EXPECT_EQ(pacer.waitForScanout(1'000 + 41'000'000), 1'000 + 50'000'000);
}

TEST(RuntimeDesigns, ParseListsAndRejectUnknownNames) {
    auto d = parseDesignList("local,qvr");
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->size(), 2u);
    EXPECT_FALSE(parseDesignList("local,dfr").ok());
    EXPECT_FALSE(parseDesignList("").ok());
}

TEST(Runtime, QvrFramesComeFromTheServerOnACleanLink) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    const HeadsetResult r = runOn(headsetConfig(RuntimeDesign::kFfr, (*server)->port(), "raw", 30));
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

TEST(Runtime, WrongKeyIsRefusedAndTheHeadsetRendersLocally) {
    auto server = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(server.ok()) << server.error();
    HeadsetConfig h = headsetConfig(RuntimeDesign::kQvr, (*server)->port(), "raw", 12);
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
    const HeadsetResult r = runOn(headsetConfig(RuntimeDesign::kFfr, port, "raw", 20));
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
    const HeadsetResult r =
        runOn(headsetConfig(RuntimeDesign::kFfr, (*server)->port(), "x264", frames));
    EXPECT_EQ(r.summary.frames_displayed, frames);
    EXPECT_GT(r.summary.frames_reused, 0);
    EXPECT_GT(r.stats.streams_lost + r.stats.decode_failures, 0u);
    // Fresh remote frames keep arriving through the last third (key frames repair the streams).
    int fresh_late = 0;
    for (int i = 2 * frames / 3; i < frames; ++i)
        fresh_late += r.frames[static_cast<size_t>(i)].reused ? 0 : 1;
    EXPECT_GT(fresh_late, 5);
    EXPECT_GT(r.stats.key_frame_requests + r.stats.net.key_frame_requests_sent, 0u);
}

TEST(Runtime, KillingTheServerLeavesTheHeadsetDisplayingAndItReconnects) {
    auto first = RenderServer::start(serverConfig("none", "raw"), world().scene);
    ASSERT_TRUE(first.ok()) << first.error();
    std::unique_ptr<RenderServer> server = std::move(*first);
    const uint16_t port = server->port();
    const int frames = 150;
    HeadsetConfig h = headsetConfig(RuntimeDesign::kQvr, port, "raw", frames);
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

TEST(Runtime, LteChoosesALargerMeanFoveaThan5g) {
    if (!glAvailable())
        GTEST_SKIP() << "no EGL/OpenGL 4.5 here";
    // The raw codec makes the periphery heavy enough (4 bytes a pixel) that the link, not the
    // server's render, decides T_remote: LIWC must move work to the headset on the slower link.
    auto run = [](const std::string& link) {
        auto server = RenderServer::start(serverConfig(link, "raw", true), world().scene);
        EXPECT_TRUE(server.ok());
        if (!server)
            return 0.0;
        const HeadsetResult r =
            runOn(headsetConfig(RuntimeDesign::kQvr, (*server)->port(), "raw", 90, true));
        EXPECT_EQ(r.summary.frames_displayed, 90);
        return meanE1(r, 30);
    };
    const double e1_lte = run("lte");
    const double e1_5g = run("5g");
    EXPECT_GT(e1_lte, e1_5g + 1.0) << "lte " << e1_lte << " vs 5g " << e1_5g;
}

}  // namespace
}  // namespace qvr::runtime
