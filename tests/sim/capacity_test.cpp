// Capacity planning (sim/capacity.h): the factors on each side's costs, the count at a target,
// and the model's headset counts against the closed form of a server-bound design.
#include "qvr/sim/capacity.h"

#include <gtest/gtest.h>

namespace qvr {
namespace {

WorkloadTrace flatTrace(int frames) {
    WorkloadTrace t;
    t.header.name = "flat";
    t.header.profile = defaultHmdProfile();
    t.header.profile.width_px = 320;
    t.header.profile.height_px = 360;
    t.header.ring_deg = 1.0;
    t.header.rings = 120;
    t.header.scales = {1, 2, 4, 8, 16, 32};
    for (int i = 0; i < frames; ++i) {
        WorkloadFrame f;
        f.index = i;
        f.time_ms = 1000.0 * i / 90.0;
        f.triangles_per_ring.assign(120, 100.0);
        f.pixels_per_ring.assign(120, 1000.0);
        f.bits_per_pixel.assign(6, 0.1);
        t.frames.push_back(f);
    }
    return t;
}

// Only the server's layer render costs: remote is server-bound (two layers a frame).
RuntimeCosts serverBoundCosts(double server_layer_ms) {
    RuntimeCosts c;
    c.decision = {0, 0, 0};
    c.fovea = {0.5, 0, 0};
    c.decode = {0, 0, 0};
    c.uca = {0.5, 0, 0};
    c.frame_overhead_ms = 0.0;
    c.server_render = {server_layer_ms, 0, 0};
    c.encode = {0, 0, 0};
    c.server_frame_ms = 0.0;
    c.link_delay_ms = 0.0;
    return c;
}

CapacityOptions remoteOptions(double target_fps) {
    CapacityOptions o;
    o.design = Design::Remote;
    o.target_fps = target_fps;
    o.net = "rate:100000";
    o.frames = 120;
    o.max_headsets = 8;
    return o;
}

TEST(CapacityFactors, ServerTimesNHeadsetByShare) {
    const SideFactors own = capacityFactors(4, 0.25, false);
    EXPECT_DOUBLE_EQ(own.server, 4.0);
    EXPECT_DOUBLE_EQ(own.headset, 4.0);
    EXPECT_DOUBLE_EQ(capacityFactors(3, 1.0, false).headset, 1.0);
    // On one shared core the headsets take turns once they are more than 1/share.
    EXPECT_DOUBLE_EQ(capacityFactors(3, 1.0, true).headset, 3.0);
    EXPECT_DOUBLE_EQ(capacityFactors(2, 0.25, true).headset, 4.0);
    EXPECT_DOUBLE_EQ(capacityFactors(6, 0.25, true).headset, 6.0);
}

CapacityPoint point(int n, double fps) {
    CapacityPoint p;
    p.headsets = n;
    p.summary.fps_mean = fps;
    return p;
}

TEST(HeadsetsAtTarget, LastCountFromOneAtTheTarget) {
    EXPECT_EQ(headsetsAtTarget({point(1, 90), point(2, 60), point(3, 45)}, 50.0), 2);
    EXPECT_EQ(headsetsAtTarget({point(1, 90), point(2, 60), point(3, 45)}, 30.0), 3);
    EXPECT_EQ(headsetsAtTarget({point(1, 20)}, 30.0), 0);
    // A later count over the target after one below it does not count.
    EXPECT_EQ(headsetsAtTarget({point(1, 60), point(2, 20), point(3, 40)}, 30.0), 1);
}

TEST(PredictCapacity, ServerBoundRemoteFollowsOneOverN) {
    // 2 layers × 7 ms: the server serves a frame in 14 ms, N headsets each every 14·N ms.
    const auto r = predictCapacity(flatTrace(120), serverBoundCosts(7.0), remoteOptions(20.0));
    ASSERT_TRUE(r) << r.error();
    ASSERT_GE(r->points.size(), 3u);
    for (size_t i = 1; i < r->points.size(); ++i)
        EXPECT_LT(r->points[i].summary.fps_mean, r->points[i - 1].summary.fps_mean + 1e-9);
    for (const CapacityPoint& p : r->points) {
        if (p.headsets < 2)
            continue;
        const double closed = 1000.0 / (14.0 * p.headsets);
        EXPECT_NEAR(p.summary.fps_mean, closed, 0.15 * closed) << p.headsets << " headsets";
        EXPECT_NEAR(p.server_utilisation, 1.0, 0.15) << p.headsets << " headsets";
    }
    // 1000 / (14 · 3) = 23.8 ≥ 20 > 1000 / (14 · 4) = 17.9.
    EXPECT_EQ(r->headsets, 3);
}

TEST(PredictCapacity, AMachineAtAnotherSpeedScalesTheCalibratedTimes) {
    // The server at 1.5x the calibration's times: 21 ms a frame, N headsets each every 21·N ms
    // (one at 47.6 FPS, two at 23.8, three at 15.9).
    CapacityOptions o = remoteOptions(20.0);
    o.speed = {1.0, 1.5};
    const auto r = predictCapacity(flatTrace(120), serverBoundCosts(7.0), o);
    ASSERT_TRUE(r) << r.error();
    EXPECT_EQ(r->headsets, 2);
    ASSERT_GE(r->points.size(), 2u);
    EXPECT_NEAR(r->points[1].summary.fps_mean, 1000.0 / 42.0, 0.15 * 1000.0 / 42.0);
    // Per headset-frame the server takes the slower machine's 21 ms, not the calibration's 14.
    EXPECT_NEAR(r->points[1].summary.server_busy_ms_mean / r->points[1].factors.server, 21.0, 1e-6);
    // The same as the calibration with every server time 1.5x.
    const auto scaled = predictCapacity(flatTrace(120), serverBoundCosts(7.0).atSpeed(1.0, 1.5),
                                        remoteOptions(20.0));
    ASSERT_TRUE(scaled) << scaled.error();
    ASSERT_EQ(scaled->points.size(), r->points.size());
    for (size_t i = 0; i < r->points.size(); ++i)
        EXPECT_DOUBLE_EQ(scaled->points[i].summary.fps_mean, r->points[i].summary.fps_mean);
}

TEST(PredictCapacity, ChargesTheTrianglesTheCallerSaysEachLayerDraws) {
    // 1 ms per thousand triangles and nothing else on the server. On the flat trace's rings
    // remote's frame is light enough for several headsets at 20 FPS. Counted as drawn (qvr
    // capacity --scene) at 20,000 triangles an eye it is 40 ms a frame: 25 FPS for one
    // headset, 12.5 for two.
    RuntimeCosts c = serverBoundCosts(0.0);
    c.server_render = {0.0, 0.0, 1.0};
    const auto rings = predictCapacity(flatTrace(120), c, remoteOptions(20.0));
    ASSERT_TRUE(rings) << rings.error();
    EXPECT_GE(rings->headsets, 3);
    int calls = 0;
    const auto drawn =
        predictCapacity(flatTrace(120), c, remoteOptions(20.0),
                        [&calls](int64_t, const LayerPlan&, int, int) { return ++calls, 20000.0; });
    ASSERT_TRUE(drawn) << drawn.error();
    EXPECT_GT(calls, 0);
    EXPECT_EQ(drawn->headsets, 1);
    ASSERT_FALSE(drawn->points.empty());
    EXPECT_NEAR(drawn->points[0].summary.server_busy_ms_mean, 40.0, 1e-6);
}

TEST(PredictCapacity, StopsAfterTwoCountsBelowTheTarget) {
    const auto r = predictCapacity(flatTrace(120), serverBoundCosts(7.0), remoteOptions(60.0));
    ASSERT_TRUE(r) << r.error();
    EXPECT_EQ(r->headsets, 1);
    EXPECT_EQ(r->points.size(), 3u);
}

TEST(PredictCapacity, EveryCountWhenAsked) {
    CapacityOptions o = remoteOptions(60.0);
    o.every_count = true;
    o.max_headsets = 5;
    const auto r = predictCapacity(flatTrace(120), serverBoundCosts(7.0), o);
    ASSERT_TRUE(r) << r.error();
    EXPECT_EQ(r->points.size(), 5u);
    EXPECT_EQ(r->headsets, 1);
}

TEST(CapacityOutput, TextAndJsonSayTheCountAtTheTarget) {
    const CapacityOptions o = remoteOptions(20.0);
    const auto r = predictCapacity(flatTrace(120), serverBoundCosts(7.0), o);
    ASSERT_TRUE(r) << r.error();
    EXPECT_NE(capacityText(*r, o).find("3 headsets per server at 20 FPS"), std::string::npos)
        << capacityText(*r, o);
    const std::string json = capacityJson(*r, o);
    EXPECT_NE(json.find("\"headsets_at_target\": 3"), std::string::npos) << json;
    EXPECT_NE(json.find("\"server_ms_per_headset_frame\""), std::string::npos);
    EXPECT_NE(json.find("\"design\": \"remote\""), std::string::npos);
}

TEST(PredictCapacity, RefusesANonPositiveTarget) {
    EXPECT_FALSE(predictCapacity(flatTrace(10), serverBoundCosts(7.0), remoteOptions(0.0)));
}

}  // namespace
}  // namespace qvr
