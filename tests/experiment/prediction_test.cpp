// The prediction step of `qvr run` without processes: the design names on the simulator's, the
// errors between predicted and measured, the speed factors, and one design predicted on a
// hand-made workload with hand-made costs.
#include "qvr/experiment/prediction.h"

#include "qvr/runtime/cpu_share.h"

#include <cmath>

#include <gtest/gtest.h>

namespace qvr::experiment {
namespace {

TEST(SimDesignOf, MapsTheRuntimeNamesOnTheSimulatorsDesigns) {
    Design d = Design::Local;
    double e1 = 0.0;
    ASSERT_TRUE(simDesignOf("fixed:12.5", d, e1));
    EXPECT_EQ(d, Design::Ffr);
    EXPECT_DOUBLE_EQ(e1, 12.5);
    e1 = 7.0;
    ASSERT_TRUE(simDesignOf("qvr", d, e1));
    EXPECT_EQ(d, Design::Qvr);
    EXPECT_DOUBLE_EQ(e1, 7.0);  // untouched
    ASSERT_TRUE(simDesignOf("local", d, e1));
    EXPECT_EQ(d, Design::Local);
    ASSERT_TRUE(simDesignOf("remote", d, e1));
    EXPECT_EQ(d, Design::Remote);
    ASSERT_TRUE(simDesignOf("sw", d, e1));
    EXPECT_EQ(d, Design::Sw);
    ASSERT_TRUE(simDesignOf("ffr", d, e1));
    EXPECT_EQ(d, Design::Ffr);
    EXPECT_FALSE(simDesignOf("fixed:", d, e1));
    EXPECT_FALSE(simDesignOf("fixed:0", d, e1));
    EXPECT_FALSE(simDesignOf("fixed:5x", d, e1));
    EXPECT_FALSE(simDesignOf("nonesuch", d, e1));
}

TEST(Metrics, KeysAndValuesInSummaryOrder) {
    const DesignMetrics m{60.0, 20.0, 30.0, 1000.0, 9.0, 11.0, std::nullopt};
    const char* keys[] = {
        "fps_mean",    "mtp_ms_mean",          "mtp_ms_p99",         "bytes_per_frame_mean",
        "e1_deg_mean", "headset_busy_ms_mean", "server_busy_ms_mean"};
    const std::optional<double> values[] = {60.0, 20.0, 30.0, 1000.0, 9.0, 11.0, std::nullopt};
    for (size_t i = 0; i < kComparedMetrics.size(); ++i) {
        EXPECT_STREQ(metricKey(kComparedMetrics[i]), keys[i]);
        EXPECT_EQ(m.value(kComparedMetrics[i]), values[i]) << keys[i];
    }
}

TEST(Metrics, MeasuredHasNoHeadsetBusyWithoutFramesThatCountIt) {
    runtime::DesignSummary s;
    s.fps_mean = 50.0;
    s.e1_deg_mean = 8.0;
    s.headset_busy_ms_mean = 12.0;
    s.headset_busy_frames = 0;
    DesignMetrics m = measuredMetrics(s, 4.0);
    EXPECT_DOUBLE_EQ(m.fps_mean, 50.0);
    EXPECT_DOUBLE_EQ(m.e1_deg_mean, 8.0);
    EXPECT_FALSE(m.headset_busy_ms_mean);
    EXPECT_EQ(m.server_busy_ms_mean, 4.0);
    s.headset_busy_frames = 3;
    m = measuredMetrics(s, std::nullopt);
    EXPECT_EQ(m.headset_busy_ms_mean, 12.0);
    EXPECT_FALSE(m.server_busy_ms_mean);
}

TEST(PredictionError, SignedPercentOfTheMeasurementAndE1InDegrees) {
    const DesignMetrics predicted{110.0, 18.0, 30.0, 500.0, 12.0, 9.0, 3.0};
    const DesignMetrics measured{100.0, 20.0, 0.0, 400.0, 10.0, std::nullopt, 4.0};
    const PredictionError e = predictionError(predicted, measured);
    EXPECT_NEAR(*e.pctOf(Metric::kFps), 10.0, 1e-12);
    EXPECT_NEAR(*e.pctOf(Metric::kMtpMean), -10.0, 1e-12);
    EXPECT_FALSE(e.pctOf(Metric::kMtpP99));  // measured 0
    EXPECT_NEAR(*e.pctOf(Metric::kBytes), 25.0, 1e-12);
    EXPECT_NEAR(*e.pctOf(Metric::kE1), 20.0, 1e-12);
    EXPECT_FALSE(e.pctOf(Metric::kHeadsetBusy));  // not measured
    EXPECT_NEAR(*e.pctOf(Metric::kServerBusy), -25.0, 1e-12);
    EXPECT_DOUBLE_EQ(e.e1_deg_abs, 2.0);
    // A model without a side's cost has no error for it.
    const DesignMetrics paper{110.0, 18.0, 30.0, 500.0, 12.0, std::nullopt, std::nullopt};
    EXPECT_FALSE(predictionError(paper, measured).pctOf(Metric::kServerBusy));
}

TEST(SpeedFactors, TheProbesMeanOverTheReference) {
    RuntimeCosts costs;
    costs.speed_reference_headset_ms = 10.0;
    costs.speed_reference_server_ms = 20.0;
    DesignRun run;
    EXPECT_FALSE(speedFactors(run, costs));  // no probes
    run.speed_before = SpeedSample{11.0, 20.0};
    run.speed_after = SpeedSample{13.0, 30.0};
    const auto f = speedFactors(run, costs);
    ASSERT_TRUE(f);
    EXPECT_DOUBLE_EQ(f->headset, 1.2);
    EXPECT_DOUBLE_EQ(f->server, 1.25);
    run.speed_after.reset();
    EXPECT_DOUBLE_EQ(speedFactors(run, costs)->headset, 1.1);
    costs.speed_reference_server_ms = 0.0;
    EXPECT_FALSE(speedFactors(run, costs));  // no reference
}

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

RuntimeCosts flatCosts() {
    RuntimeCosts c;
    c.decision = {0, 0, 0};
    c.fovea = {20.0, 0, 0};
    c.decode = {0, 0, 0};
    c.uca = {5.0, 0, 0};
    c.frame_overhead_ms = 0.0;
    c.server_render = {10.0, 0, 0};
    c.encode = {0, 0, 0};
    c.server_frame_ms = 0.0;
    c.link_delay_ms = 0.0;
    return c;
}

TEST(ServerFragmentsOf, TheRunsOverdrawPerPixelFromTheNearestCountedFrame) {
    // Stream 0 counted at frames 1 (4 a pixel) and 5 (8 a pixel); stream 3 never.
    std::vector<std::array<double, 4>> per_px(7, {-1.0, -1.0, -1.0, -1.0});
    per_px[1][0] = 4.0;
    per_px[5][0] = 8.0;
    const ServerFragmentsFn f = serverFragmentsOf(per_px);
    ASSERT_TRUE(f);
    EXPECT_EQ(f(1, 0, 1000.0), 4000.0);  // its own count, times the model's pixels
    EXPECT_EQ(f(0, 0, 1000.0), 4000.0);  // before the first count: the first
    EXPECT_EQ(f(2, 0, 1000.0), 4000.0);  // nearer frame 1 than frame 5
    EXPECT_EQ(f(4, 0, 1000.0), 8000.0);
    EXPECT_EQ(f(90, 0, 10.0), 80.0);  // past the run: its last count
    EXPECT_EQ(f(-3, 0, 10.0), 40.0);
    EXPECT_EQ(f(2, 3, 1000.0), -1.0);  // a stream never counted: the law's mean
    EXPECT_EQ(f(2, 7, 1000.0), -1.0);  // no such stream
    // Nothing counted (a design with no server frames): no function at all.
    EXPECT_FALSE(serverFragmentsOf({}));
    EXPECT_FALSE(serverFragmentsOf(std::vector<std::array<double, 4>>(3, {-1, -1, -1, -1})));
}

TEST(PredictDesign, RunsTheCalibratedModelAsTheRunWasSetUp) {
    const WorkloadTrace trace = flatTrace(60);
    const RuntimeCosts costs = flatCosts();
    ModelSettings settings;
    settings.net = "rate:100";
    settings.warmup_frames = 5;
    std::vector<RuntimeFrame> frames;
    const DesignPrediction p = predictDesign(trace, {"local", std::nullopt, {}, {}, {}}, costs,
                                             settings, std::nullopt, &frames);
    ASSERT_TRUE(p.calibrated);
    EXPECT_FALSE(p.at_probe_speed);
    EXPECT_FALSE(p.paper_hardware);
    EXPECT_EQ(frames.size(), 60u);
    // The same model, set up by hand.
    RuntimeSimConfig rc;
    rc.design = Design::Local;
    rc.costs = costs;
    rc.frames = 60;
    rc.warmup_frames = 5;
    auto link = makeRuntimeLink("rate:100", nullptr);
    const RuntimeSummary direct = simulateRuntime(trace, rc, **link).summary;
    EXPECT_DOUBLE_EQ(p.calibrated->metrics.fps_mean, direct.fps_mean);
    EXPECT_DOUBLE_EQ(p.calibrated->metrics.mtp_ms_mean, direct.mtp_ms_mean);
    EXPECT_EQ(p.calibrated->metrics.headset_busy_ms_mean, direct.headset_busy_ms_mean);
    EXPECT_EQ(p.calibrated->frames_reused, direct.frames_reused);
}

TEST(PredictDesign, ChargesTheLinksDelayAndTheProbesSpeed) {
    const WorkloadTrace trace = flatTrace(60);
    const RuntimeCosts costs = flatCosts();
    ModelSettings settings;
    settings.net = "rate:100";
    settings.pipeline_depth = 1;  // one frame at a time: the delay is on every frame's path
    const DesignModelInputs remote{"remote", SideFactors{2.0, 2.0}, {}, {}, {}};
    const DesignPrediction fast = predictDesign(trace, remote, costs, settings, std::nullopt);
    settings.net = "rate:100,delay_ms=30";
    const DesignPrediction slow = predictDesign(trace, remote, costs, settings, std::nullopt);
    ASSERT_TRUE(fast.calibrated && slow.calibrated);
    EXPECT_GT(slow.calibrated->metrics.mtp_ms_mean, fast.calibrated->metrics.mtp_ms_mean + 25.0);
    // At twice the calibration's times the model runs slower than calibrated.
    ASSERT_TRUE(fast.at_probe_speed);
    ASSERT_TRUE(fast.speed);
    EXPECT_DOUBLE_EQ(fast.speed->headset, 2.0);
    EXPECT_LT(fast.at_probe_speed->fps_mean, fast.calibrated->metrics.fps_mean);
    EXPECT_GT(fast.at_probe_speed->mtp_ms_mean, fast.calibrated->metrics.mtp_ms_mean);
}

TEST(PredictDesign, AHeadsetShareRunsTheHeadsetUnderItsQuota) {
    const WorkloadTrace trace = flatTrace(60);
    const RuntimeCosts costs = flatCosts();
    ModelSettings settings;
    settings.net = "rate:100";
    const DesignPrediction whole =
        predictDesign(trace, {"local", std::nullopt, {}, {}, {}}, costs, settings, std::nullopt);
    settings.headset_share = 0.5;
    const DesignPrediction half =
        predictDesign(trace, {"local", std::nullopt, {}, {}, {}}, costs, settings, std::nullopt);
    ASSERT_TRUE(whole.calibrated && half.calibrated);
    EXPECT_LT(half.calibrated->metrics.fps_mean, 0.6 * whole.calibrated->metrics.fps_mean);
    // The runtime model with the runtime's quota: half of every CFS period.
    RuntimeSimConfig rc;
    rc.design = Design::Local;
    rc.costs = costs;
    rc.frames = 60;
    rc.headset_share = 0.5;
    rc.quota_period_ms = runtime::CpuShareGroup::kDefaultPeriodUs * 1e-3;
    auto link = makeRuntimeLink("rate:100", nullptr);
    const RuntimeSummary direct = simulateRuntime(trace, rc, **link).summary;
    EXPECT_DOUBLE_EQ(half.calibrated->metrics.fps_mean, direct.fps_mean);
    EXPECT_DOUBLE_EQ(half.calibrated->metrics.mtp_ms_mean, direct.mtp_ms_mean);
    // Local never idles: within a period of a headset at half speed.
    settings.headset_share = 1.0;
    const DesignPrediction by_hand = predictDesign(trace, {"local", std::nullopt, {}, {}, {}},
                                                   costs.atSpeed(2.0, 1.0), settings, std::nullopt);
    ASSERT_TRUE(by_hand.calibrated);
    EXPECT_NEAR(half.calibrated->metrics.mtp_ms_mean, by_hand.calibrated->metrics.mtp_ms_mean,
                rc.quota_period_ms);
    RunOptions plan;
    plan.headset_share = 0.4;
    EXPECT_DOUBLE_EQ(modelSettings(plan).headset_share, 0.4);
}

TEST(PredictDesign, PaperHardwareOnlyWithANetworkAndNothingForAnUnknownDesign) {
    const WorkloadTrace trace = flatTrace(30);
    ModelSettings settings;
    settings.net = "wifi";
    auto wifi = networkSpecByName("wifi");
    ASSERT_TRUE(wifi);
    const DesignPrediction p =
        predictDesign(trace, {"ffr", std::nullopt, {}, {}, {}}, flatCosts(), settings, *wifi);
    ASSERT_TRUE(p.paper_hardware);
    EXPECT_GT(p.paper_hardware->fps_mean, 0.0);
    EXPECT_FALSE(p.paper_hardware->headset_busy_ms_mean);
    settings.net = "nonesuch";  // no calibrated prediction on a link the model cannot make
    const DesignPrediction no_link =
        predictDesign(trace, {"ffr", std::nullopt, {}, {}, {}}, flatCosts(), settings, *wifi);
    EXPECT_FALSE(no_link.calibrated);
    EXPECT_TRUE(no_link.paper_hardware);
    const DesignPrediction none =
        predictDesign(trace, {"nonesuch", SideFactors{}, {}, {}, {}}, flatCosts(), settings, *wifi);
    EXPECT_FALSE(none.calibrated || none.paper_hardware || none.speed);
}

}  // namespace
}  // namespace qvr::experiment
