// The server's and headset's configurations from the command line's settings
// (runtime/session_settings.h), and the serving loop (runtime/serve_loop.h).
#include "qvr/runtime/session_settings.h"

#include <gtest/gtest.h>

#include <chrono>

#include <glm/geometric.hpp>

#include "qvr/runtime/serve_loop.h"
#include "qvr/runtime/session.h"

namespace qvr::runtime {
namespace {

constexpr const char* kKey = "pass:test";

TEST(SessionSettings, ServerConfigTakesTheSettingsAndKeepsRecordsOnlyWhenAsked) {
    ServerSettings s;
    s.key = kKey;
    s.port = 7411;
    s.profile = "small";
    s.net = "wifi";
    s.no_holes = true;
    auto cfg = renderServerConfig(s);
    ASSERT_TRUE(cfg) << cfg.error();
    EXPECT_EQ(cfg->net.port, 7411);
    EXPECT_EQ(cfg->profile.width_px, 320);
    EXPECT_FALSE(cfg->holes.enabled);
    EXPECT_EQ(cfg->max_frame_records, 0u);
    s.keep_frame_records = true;
    EXPECT_GT(renderServerConfig(s)->max_frame_records, 0u);
    s.net = "bogus";
    auto bad = renderServerConfig(s);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().rfind("--net: ", 0), 0u);
    s.key = "";
    EXPECT_FALSE(renderServerConfig(s));
}

TEST(SessionSettings, HeadsetConfigParsesTheDesignAndProfile) {
    HeadsetSettings s;
    s.key = kKey;
    s.host = "127.0.0.1";
    s.design = "fixed:10";
    s.profile = "run";
    s.frames = 12;
    auto hc = headsetConfig(s);
    ASSERT_TRUE(hc) << hc.error();
    EXPECT_EQ(hc->design, Design::Fixed);
    EXPECT_DOUBLE_EQ(hc->fixed_e1_deg, 10.0);
    EXPECT_EQ(hc->profile.width_px, 480);
    EXPECT_EQ(hc->frames, 12);
    s.design = "static";  // the simulator's alone
    auto bad = headsetConfig(s);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().rfind("--design: ", 0), 0u);
}

TEST(PlayAhead, GivesAtEachTimeWhatTheTracesGaveThatMuchLater) {
    auto base = loadHeadsetInputs("builtin:room", "default", "model", 90.0, 60, 4);
    ASSERT_TRUE(base) << base.error();
    HeadsetTraces ahead = base->traces;
    playAhead(ahead, 3.7);
    for (double t : {0.0, 11.1, 250.0, 600.0}) {
        const Pose a = poseAt(ahead.motion, t), b = poseAt(base->traces.motion, t + 3.7);
        EXPECT_NEAR(glm::length(a.position_m - b.position_m), 0.0, 1e-6) << t;
        EXPECT_NEAR(std::fabs(glm::dot(a.orientation, b.orientation)), 1.0, 1e-6) << t;
        const Gaze ga = gazeAt(ahead.gaze, t), gb = gazeAt(base->traces.gaze, t + 3.7);
        EXPECT_NEAR(ga.x_deg, gb.x_deg, 1e-9) << t;
        EXPECT_NEAR(ga.y_deg, gb.y_deg, 1e-9) << t;
    }
    // A fraction of a frame ahead is a different pose while the head moves.
    const Pose a = poseAt(ahead.motion, 300.0), b = poseAt(base->traces.motion, 300.0);
    EXPECT_GT(glm::length(a.position_m - b.position_m) +
                  (1.0 - std::fabs(glm::dot(a.orientation, b.orientation))),
              1e-7);
}

TEST(ServeLoop, StopsAtTheDurationOrWhenStopped) {
    std::atomic<bool> stop{false};
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_TRUE(serveUntilStopped(stop, 0.15, nullptr, {}));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GE(s, 0.15);
    EXPECT_LT(s, 5.0);
    stop = true;
    EXPECT_TRUE(serveUntilStopped(stop, 0.0, nullptr, {}));
    EXPECT_FALSE(agonesSdkOptions("not-a-port"));
    EXPECT_EQ(agonesSdkOptions("9358")->port, 9358);
}

}  // namespace
}  // namespace qvr::runtime
