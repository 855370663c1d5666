// The policies LIWC is compared with (paper §6): fixed e1, the software-reactive policy that
// sees measurements lag_frames late (Fig. 4), and the oracle; and makePolicy's names.
#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/controller/control_run.h"
#include "qvr/controller/policy.h"

namespace qvr {
namespace {

using ::testing::HasSubstr;

WorkloadHeader defaultHeader() {
    WorkloadHeader h;
    h.profile = defaultHmdProfile();
    h.ring_deg = 1.0;
    h.rings = 100;
    h.scales = {1, 2, 4, 8, 16, 32};
    return h;
}

// A frame the software policy may look at: only its gaze (it must not need the rings).
WorkloadFrame bareFrame(int64_t index) {
    WorkloadFrame f;
    f.index = index;
    f.gaze = {0, 0};
    return f;
}

// A measurement at e1 = 5° whose remote side is far slower than its local side.
FrameMeasurement remoteBound(int64_t index, double e1_deg) {
    FrameMeasurement m;
    m.index = index;
    m.e1_deg = e1_deg;
    m.t_local_ms = 1.0;
    m.t_remote_ms = 50.0;
    m.throughput_bps = 100e6;
    m.middle_pixels = 2.0e5;
    m.outer_pixels = 2.0e5;
    // 50 ms at 100 Mbit/s is 625 000 bytes, split over the two layers.
    m.middle_bytes = 312'500.0;
    m.outer_bytes = 312'500.0;
    m.s1 = 1.5;
    m.s2 = 8.0;
    return m;
}

// The start-up no policy learns from: the frames before any completed, and for frames that ask
// the server for layers, every one up to the first composed from them — however late that is.
TEST(StartUpFrame, LastsUntilTheFirstCompositionFromTheServersLayers) {
    EXPECT_TRUE(isStartUpFrame(0, 2, false, -1));
    EXPECT_TRUE(isStartUpFrame(1, 2, false, -1));
    EXPECT_FALSE(isStartUpFrame(2, 2, false, -1));  // all local: only the pipeline's fill
    EXPECT_TRUE(isStartUpFrame(5, 2, true, -1));    // no layers composed yet
    EXPECT_TRUE(isStartUpFrame(3, 2, true, 3));     // the first composition itself
    EXPECT_FALSE(isStartUpFrame(4, 2, true, 3));
    EXPECT_TRUE(isStartUpFrame(1, 2, true, 0));  // composed early: the pipeline's fill still is
}

TEST(FixedPolicy, KeepsE1WhenFramesChange) {
    FixedPolicy fixed;
    EXPECT_EQ(fixed.name(), "fixed");
    for (int i = 0; i < 10; ++i) {
        const Decision d = fixed.decide(bareFrame(i));
        EXPECT_EQ(d.e1_deg, 5.0);
        EXPECT_TRUE(std::isnan(d.t_local_pred_ms));
        EXPECT_TRUE(std::isnan(d.t_remote_pred_ms));
        fixed.observe(remoteBound(i, 5.0));
    }
    FixedPolicy seven(7.5);
    EXPECT_EQ(seven.decide(bareFrame(0)).e1_deg, 7.5);
}

// Runs the software-reactive policy over hand-built measurements and returns the frame at which
// e1 first leaves its initial value.
int firstChange(int lag_frames) {
    const WorkloadHeader h = defaultHeader();
    SoftwareReactiveConfig c;
    c.lag_frames = lag_frames;
    auto sw = makeSoftwareReactivePolicy(h, c);
    EXPECT_EQ(sw->name(), "sw");
    for (int i = 0; i < 10; ++i) {
        const Decision d = sw->decide(bareFrame(i));
        if (d.e1_deg != c.e1_initial_deg)
            return i;
        sw->observe(remoteBound(i, d.e1_deg));
    }
    return -1;
}

TEST(SoftwareReactivePolicy, WaitsForLagFramesWhenMeasurementsArrive) {
    // Frame 0's measurement reaches software only when it is lag_frames old.
    EXPECT_EQ(firstChange(2), 2);
    EXPECT_EQ(firstChange(3), 3);
    EXPECT_EQ(firstChange(1), 1);
}

TEST(SoftwareReactivePolicy, MovesTowardsBalanceByBoundedStepsWhenRemoteIsSlow) {
    const WorkloadHeader h = defaultHeader();
    SoftwareReactiveConfig c;
    auto sw = makeSoftwareReactivePolicy(h, c);
    double prev = c.e1_initial_deg;
    for (int i = 0; i < 8; ++i) {
        const Decision d = sw->decide(bareFrame(i));
        EXPECT_LE(std::fabs(d.e1_deg - prev), c.max_step_deg + 1e-9);
        EXPECT_GE(d.e1_deg, prev - 1e-9) << "a remote-bound frame must not shrink the fovea";
        prev = d.e1_deg;
        sw->observe(remoteBound(i, d.e1_deg));
    }
    EXPECT_GT(prev, c.e1_initial_deg);
}

TEST(SoftwareReactivePolicy, ShrinksFoveaByBoundedStepsWhenLocalIsSlow) {
    const WorkloadHeader h = defaultHeader();
    SoftwareReactiveConfig c;
    c.e1_initial_deg = 30.0;
    auto sw = makeSoftwareReactivePolicy(h, c);
    double prev = c.e1_initial_deg;
    for (int i = 0; i < 8; ++i) {
        const Decision d = sw->decide(bareFrame(i));
        EXPECT_LE(std::fabs(d.e1_deg - prev), c.max_step_deg + 1e-9);
        EXPECT_LE(d.e1_deg, prev + 1e-9) << "a local-bound frame must not grow the fovea";
        EXPECT_GE(d.e1_deg, c.e1_min_deg);
        prev = d.e1_deg;
        FrameMeasurement m = remoteBound(i, d.e1_deg);
        m.t_local_ms = 50.0;
        m.t_remote_ms = 1.0;
        m.middle_bytes = m.outer_bytes = 6'250.0;  // 1 ms at 100 Mbit/s
        sw->observe(m);
    }
    EXPECT_LT(prev, c.e1_initial_deg - c.max_step_deg);
}

TEST(SoftwareReactivePolicy, KeepsInitialE1WhenNothingIsMeasured) {
    auto sw = makeSoftwareReactivePolicy(defaultHeader());
    for (int i = 0; i < 5; ++i)
        EXPECT_EQ(sw->decide(bareFrame(i)).e1_deg, 5.0);
}

// A frame with a workload for the oracle: ring k holds 3000·(k+1) triangles.
WorkloadFrame workFrame(const WorkloadHeader& h, Gaze gaze) {
    WorkloadFrame f;
    f.gaze = gaze;
    for (int k = 0; k < h.rings; ++k) {
        f.triangles_per_ring.push_back(3000.0 * (k + 1));
        f.pixels_per_ring.push_back(40000.0);
    }
    for (double s : h.scales)
        f.bits_per_pixel.push_back(0.6 * std::pow(s, 0.7));
    return f;
}

TEST(OraclePolicy, BeatsEveryE1OnFineGridWhenDeciding) {
    const WorkloadHeader h = defaultHeader();
    const CostModel truth(h, GpuModel{}, 137.6e6);
    auto oracle = makeOraclePolicy(h, truth);
    EXPECT_EQ(oracle->name(), "oracle");
    for (const Gaze g : {Gaze{0, 0}, Gaze{15, -10}}) {
        const WorkloadFrame f = workFrame(h, g);
        const Decision d = oracle->decide(f);
        const FrameCost at = truth.cost(f, d.e1_deg);
        EXPECT_DOUBLE_EQ(d.t_local_pred_ms, at.local_ms);
        EXPECT_DOUBLE_EQ(d.t_remote_pred_ms, at.remote_ms);
        const double hi = std::min(90.0, truth.planner().geometry().coverEccentricityDeg(g));
        double best = INFINITY;
        for (double e = 1.0; e <= hi; e += 0.1)
            best = std::min(best, truth.cost(f, e).frameMs());
        EXPECT_LE(at.frameMs(), best * (1.0 + 1e-3)) << "gaze " << g.x_deg << "," << g.y_deg;
    }
}

TEST(MakePolicy, BuildsEachNamedPolicyWhenNameIsKnown) {
    const WorkloadHeader h = defaultHeader();
    const CostModel truth(h, GpuModel{}, 137.6e6);
    for (const char* name : {"liwc", "sw", "fixed", "oracle"}) {
        auto p = makePolicy(name, h, truth);
        ASSERT_TRUE(p.ok()) << name;
        EXPECT_EQ((*p)->name(), name);
    }
    auto fixed = makePolicy("fixed", h, truth, 9.0);
    ASSERT_TRUE(fixed.ok());
    EXPECT_EQ((*fixed)->decide(bareFrame(0)).e1_deg, 9.0);
}

TEST(MakePolicy, FailsWithNameWhenPolicyIsUnknown) {
    const WorkloadHeader h = defaultHeader();
    const CostModel truth(h, GpuModel{}, 137.6e6);
    for (const char* name : {"bogus", "", "LIWC", "oracle "}) {
        auto p = makePolicy(name, h, truth);
        ASSERT_FALSE(p.ok()) << name;
        EXPECT_THAT(p.error(), HasSubstr(std::string("'") + name + "'"));
    }
}

}  // namespace
}  // namespace qvr
