// The network-driven baseline "aimd" (EyeNexus's controller, docs/LIWC.md): a delay-gradient
// detector on each frame's one-way delay, and a controller that grows the periphery's byte budget
// additively while the link keeps up and shrinks it by a factor on overuse.
#include <gtest/gtest.h>

#include "qvr/controller/aimd.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/workload/workload.h"

namespace qvr {
namespace {

WorkloadHeader header() {
    WorkloadHeader h;
    h.profile = defaultHmdProfile();
    h.ring_deg = 1.0;
    h.rings = 100;
    h.scales = {1, 2, 4, 8, 16, 32};
    return h;
}

WorkloadFrame frame(int64_t index) {
    WorkloadFrame f;
    f.index = index;
    f.gaze = {0, 0};
    return f;
}

// What the headset measures of frame i at e1, sent every 30 ms, its one-way delay `delay_ms`.
FrameMeasurement measured(const LayerPlanner& planner, int64_t i, double e1, double delay_ms) {
    const LayerPlan plan = planner.plan({0, 0}, e1);
    FrameMeasurement m;
    m.index = i;
    m.e1_deg = e1;
    m.middle_pixels = 2.0 * double(plan.middle_pixels);
    m.outer_pixels = 2.0 * double(plan.outer_pixels);
    m.middle_bytes = m.middle_pixels * 0.5 / 8.0;
    m.outer_bytes = m.outer_pixels * 1.0 / 8.0;
    m.s1 = plan.s1;
    m.s2 = plan.s2;
    m.request_ms = 30.0 * double(i);
    m.arrival_ms = m.request_ms + delay_ms;
    return m;
}

TEST(DelayTrendDetector, ReadsASteadyDelayAsNormalAGrowingOneAsOveruseADrainingOneAsUnderuse) {
    const AimdConfig c;
    DelayTrendDetector steady(c), growing(c), draining(c);
    for (int i = 0; i < 40; ++i) {
        const double send = 30.0 * i;
        EXPECT_EQ(steady.update(send, send + 50.0), DelayTrendDetector::Usage::Normal) << i;
        growing.update(send, send + 50.0 + 3.0 * i);  // the queue grows 3 ms a frame
        draining.update(send, send + 200.0 - 3.0 * i);
    }
    EXPECT_EQ(growing.usage(), DelayTrendDetector::Usage::Overusing);
    EXPECT_GT(growing.modifiedTrend(), c.threshold);
    EXPECT_EQ(draining.usage(), DelayTrendDetector::Usage::Underusing);
    EXPECT_LT(draining.modifiedTrend(), -c.threshold);
}

// While the delay holds, C grows by 0.2 a frame (after one frame of hold) and e1 falls: more of
// the view is streamed. When the delay starts to grow, C falls by 10% a frame and e1 rises.
TEST(AimdPolicy, IncreasesTheStreamedShareAdditivelyAndCutsItMultiplicativelyOnQueueGrowth) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    AimdConfig c;
    c.e1_initial_deg = 20.0;
    AimdPolicy aimd(h, c);
    double e1 = aimd.decide(frame(0)).e1_deg;
    EXPECT_NEAR(e1, 20.0, 0.3);
    const double c0 = aimd.controller();
    ASSERT_GT(c0, c.c_min);
    ASSERT_LT(c0, c.c_max);
    std::vector<double> cs, e1s;
    for (int i = 0; i < 60; ++i) {
        aimd.observe(measured(planner, i, e1, 40.0));
        cs.push_back(aimd.controller());
        e1 = aimd.decide(frame(i + 1)).e1_deg;
        e1s.push_back(e1);
    }
    // Additive: from the fourth frame on, exactly +0.2 a frame; e1 never rises.
    for (size_t i = 4; i < cs.size(); ++i) {
        EXPECT_NEAR(cs[i] - cs[i - 1], c.c_increase, 1e-9) << i;
        EXPECT_LE(e1s[i], e1s[i - 1]) << i;
    }
    EXPECT_LT(e1s.back(), 20.0 - 1.0);
    // Now the queue grows 4 ms a frame: overuse, then ×0.9 a frame.
    const double before = aimd.controller();
    const double e1_before = e1;
    int decreases = 0;
    for (int i = 60; i < 80; ++i) {
        const double prev = aimd.controller();
        aimd.observe(measured(planner, i, e1, 40.0 + 4.0 * (i - 59)));
        if (aimd.controller() < prev) {
            EXPECT_NEAR(aimd.controller(), std::max(c.c_min, prev * c.c_decrease_factor), 1e-9);
            ++decreases;
        }
        e1 = aimd.decide(frame(i + 1)).e1_deg;
    }
    EXPECT_GE(decreases, 5);
    EXPECT_LT(aimd.controller(), 0.7 * before);
    EXPECT_GT(e1, e1_before + 2.0);
}

// A frame whose periphery did not arrive gives no delay sample: C does not move.
TEST(AimdPolicy, LeavesTheControllerAloneForAFrameWithoutArrival) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    AimdPolicy aimd(h);
    double e1 = aimd.decide(frame(0)).e1_deg;
    for (int i = 0; i < 10; ++i) {
        aimd.observe(measured(planner, i, e1, 40.0));
        e1 = aimd.decide(frame(i + 1)).e1_deg;
    }
    const double c_before = aimd.controller();
    FrameMeasurement lost = measured(planner, 10, e1, 40.0);
    lost.arrival_ms = 0.0;
    aimd.observe(lost);
    EXPECT_DOUBLE_EQ(aimd.controller(), c_before);
}

// A periphery that missed the wait limit is a loss: C falls by 10%, whatever the delays said.
TEST(AimdPolicy, CutsTheControllerForAFrameWhosePeripheryWasLate) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    AimdPolicy aimd(h);
    double e1 = aimd.decide(frame(0)).e1_deg;
    for (int i = 0; i < 10; ++i) {
        aimd.observe(measured(planner, i, e1, 40.0));
        e1 = aimd.decide(frame(i + 1)).e1_deg;
    }
    const double c_before = aimd.controller();
    FrameMeasurement late = measured(planner, 10, e1, 40.0);
    late.arrival_ms = 0.0;
    late.periphery_late = true;
    aimd.observe(late);
    EXPECT_NEAR(aimd.controller(), 0.9 * c_before, 1e-9);
}

}  // namespace
}  // namespace qvr
