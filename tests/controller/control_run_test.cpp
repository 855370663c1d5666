// Running policies over workloads (`qvr control`) and the summary other tools read: LIWC
// balances the synthetic default within 30 frames and stays within 10% of the oracle, which is
// the per-frame limit; the software-reactive and fixed policies are measurably worse; LIWC
// adapts e1 to the link (paper §4.1, §6.2).
#include "qvr/controller/control_run.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "qvr/core/link_efficiency.h"
#include "qvr/workload/synthetic.h"

namespace qvr {
namespace {

// The nominal rates at the Table 1 link efficiency, as `qvr control` runs them.
const double kWifiBps = 200e6 * calibratedLinkEfficiency();
const double kLteBps = 100e6 * calibratedLinkEfficiency();
const double k5gBps = 500e6 * calibratedLinkEfficiency();

ControlRun runNamed(const std::string& name, const WorkloadTrace& trace, const CostModel& truth) {
    auto policy = makePolicy(name, trace.header, truth);
    EXPECT_TRUE(policy.ok());
    return runPolicy(**policy, trace, truth, static_cast<int>(trace.frames.size()));
}

ControlFrame frameWith(double local_ms, double remote_ms, double e1 = 5.0) {
    ControlFrame f;
    f.t_local_ms = local_ms;
    f.t_remote_ms = remote_ms;
    f.e1_deg = e1;
    f.t_local_pred_ms = std::numeric_limits<double>::quiet_NaN();
    f.t_remote_pred_ms = std::numeric_limits<double>::quiet_NaN();
    return f;
}

TEST(Summarize, FindsFirstFrameFromWhichRatioStaysBalancedWhenItSettles) {
    // Ratios 2, 1.1, 0.9, 1.2, 1.0, 1.05: frame 3 breaks the run, so balance starts at 4.
    const std::vector<ControlFrame> frames = {frameWith(1, 2),   frameWith(10, 11),
                                              frameWith(10, 9),  frameWith(10, 12),
                                              frameWith(10, 10), frameWith(20, 21)};
    const ControlSummary s = summarize(frames);
    ASSERT_TRUE(s.frames_to_balance.has_value());
    EXPECT_EQ(*s.frames_to_balance, 4);
    EXPECT_EQ(s.frames, 6);
}

TEST(Summarize, LeavesBalanceEmptyWhenLastFrameIsUnbalanced) {
    const std::vector<ControlFrame> frames = {frameWith(10, 10), frameWith(10, 10.5),
                                              frameWith(10, 20)};
    EXPECT_FALSE(summarize(frames).frames_to_balance.has_value());
    EXPECT_FALSE(summarize({frameWith(0, 3)}).frames_to_balance.has_value());  // no local time
    EXPECT_FALSE(summarize({}).frames_to_balance.has_value());
    EXPECT_EQ(summarize({}).frames, 0);
    // The tolerance is strict: |ratio − 1| equal to it is unbalanced (1.25 = 5/4 exactly).
    EXPECT_FALSE(summarize({frameWith(4, 5)}, 0.25).frames_to_balance.has_value());
    EXPECT_TRUE(summarize({frameWith(4, 4.9)}, 0.25).frames_to_balance.has_value());
}

TEST(Summarize, StartsAtZeroWhenEveryFrameIsBalanced) {
    const std::vector<ControlFrame> frames = {frameWith(10, 9), frameWith(10, 11), frameWith(8, 8)};
    const ControlSummary s = summarize(frames);
    ASSERT_TRUE(s.frames_to_balance.has_value());
    EXPECT_EQ(*s.frames_to_balance, 0);
    // A balanced stretch that is later broken does not count.
    const std::vector<ControlFrame> broken = {frameWith(10, 10), frameWith(10, 10),
                                              frameWith(10, 30), frameWith(10, 10)};
    EXPECT_EQ(*summarize(broken).frames_to_balance, 3);
}

TEST(Summarize, AveragesFrameTimeAsMaxOfLocalAndRemoteWhenSummarising) {
    std::vector<ControlFrame> frames = {frameWith(2, 5, 4.0), frameWith(7, 3, 8.0),
                                        frameWith(4, 4, 12.0)};
    frames[0].t_local_pred_ms = 3.0;  // 50% off
    frames[1].t_local_pred_ms = 7.0;  // exact
    frames[0].remote_bytes = 100;
    frames[1].remote_bytes = 300;
    const ControlSummary s = summarize(frames);
    EXPECT_DOUBLE_EQ(s.frame_ms_mean, (5.0 + 7.0 + 4.0) / 3.0);
    EXPECT_DOUBLE_EQ(s.e1_deg_mean, 8.0);
    EXPECT_DOUBLE_EQ(s.remote_bytes_mean, 400.0 / 3.0);
    EXPECT_DOUBLE_EQ(s.frame_ms_p99, 7.0);
    EXPECT_DOUBLE_EQ(s.ratio_final, 1.0);
    // Only frames with a prediction count towards the error.
    EXPECT_DOUBLE_EQ(s.prediction_error_local_pct, 25.0);
    EXPECT_DOUBLE_EQ(s.prediction_error_remote_pct, 0.0);
}

TEST(Summarize, TakesNearestRankP99WhenFramesVary) {
    // Frame times 1…200 ms in a scrambled order: the 99th percentile by nearest rank is the
    // ceil(0.99·200) = 198th smallest, 198 ms.
    std::vector<ControlFrame> frames;
    for (int i = 0; i < 200; ++i) {
        const double ms = static_cast<double>((i * 77) % 200 + 1);
        frames.push_back(frameWith(ms, ms / 2.0));
    }
    const ControlSummary s = summarize(frames);
    EXPECT_DOUBLE_EQ(s.frame_ms_p99, 198.0);
    EXPECT_DOUBLE_EQ(s.frame_ms_mean, 100.5);
    EXPECT_DOUBLE_EQ(summarize({frameWith(3, 9)}).frame_ms_p99, 9.0);
}

// The synthetic default and every policy's run over it, computed once for the suite: the
// tests below read the same four runs (the oracle scans ~160 layer plans a frame), and each
// asserts its own property of them.
class SyntheticDefault : public ::testing::Test {
protected:
    struct Runs {
        WorkloadTrace trace = generateSyntheticWorkload(defaultSyntheticSpec());
        CostModel truth{trace.header, GpuModel{}, kWifiBps};
        ControlRun liwc = runNamed("liwc", trace, truth);
        ControlRun oracle = runNamed("oracle", trace, truth);
        ControlRun sw = runNamed("sw", trace, truth);
        ControlRun fixed = runNamed("fixed", trace, truth);
    };
    static void SetUpTestSuite() { s_runs = new Runs(); }
    static void TearDownTestSuite() {
        delete s_runs;
        s_runs = nullptr;
    }
    static const Runs& runs() { return *s_runs; }
    static inline Runs* s_runs = nullptr;
};

TEST_F(SyntheticDefault, RecordsTrueCostOfEachDecisionWhenRunning) {
    const WorkloadTrace& trace = runs().trace;
    const CostModel& truth = runs().truth;
    const ControlRun& run = runs().liwc;
    ASSERT_EQ(run.frames.size(), 300u);
    EXPECT_EQ(run.policy, "liwc");
    EXPECT_DOUBLE_EQ(run.frames[0].e1_deg, 5.0);
    for (size_t i = 0; i < run.frames.size(); i += 17) {
        const ControlFrame& f = run.frames[i];
        EXPECT_EQ(f.index, static_cast<int64_t>(i));
        const FrameCost c = truth.cost(trace.frames[i], f.e1_deg);
        EXPECT_DOUBLE_EQ(f.t_local_ms, c.local_ms);
        EXPECT_DOUBLE_EQ(f.t_remote_ms, c.remote_ms);
        EXPECT_DOUBLE_EQ(f.remote_bytes, c.bytes.total());
        EXPECT_GE(f.e2_deg, f.e1_deg);
        EXPECT_TRUE(std::isfinite(f.t_local_pred_ms));
    }
    const ControlSummary again = summarize(run.frames);
    EXPECT_DOUBLE_EQ(again.frame_ms_mean, run.summary.frame_ms_mean);
    EXPECT_EQ(again.frames_to_balance, run.summary.frames_to_balance);
    // Fewer frames than the trace holds, or more.
    auto liwc = makePolicy("liwc", trace.header, truth);
    EXPECT_EQ(runPolicy(**liwc, trace, truth, 10).frames.size(), 10u);
    auto fixed = makePolicy("fixed", trace.header, truth);
    EXPECT_EQ(runPolicy(**fixed, trace, truth, 5000).frames.size(), 300u);
}

TEST_F(SyntheticDefault, BalancesWithin30FramesWhenLiwcRuns) {
    const ControlRun& liwc = runs().liwc;
    ASSERT_TRUE(liwc.summary.frames_to_balance.has_value());
    EXPECT_LE(*liwc.summary.frames_to_balance, 30);
    for (size_t i = static_cast<size_t>(*liwc.summary.frames_to_balance); i < 300; ++i)
        EXPECT_LT(std::fabs(liwc.frames[i].ratio() - 1.0), kBalanceTolerance);
}

TEST_F(SyntheticDefault, StaysWithinTenPercentOfOracleWhenLiwcRuns) {
    const ControlRun& liwc = runs().liwc;
    const ControlRun& oracle = runs().oracle;
    EXPECT_LE(liwc.summary.frame_ms_mean, 1.10 * oracle.summary.frame_ms_mean);
    EXPECT_GE(liwc.summary.frame_ms_mean, oracle.summary.frame_ms_mean * (1.0 - 1e-9));
}

TEST_F(SyntheticDefault, IsWorseWhenSoftwareReactiveOrFixed) {
    const ControlRun& liwc = runs().liwc;
    const ControlRun& sw = runs().sw;
    const ControlRun& fixed = runs().fixed;
    EXPECT_GT(sw.summary.frame_ms_mean, 1.01 * liwc.summary.frame_ms_mean);
    EXPECT_GT(fixed.summary.frame_ms_mean, 1.01 * liwc.summary.frame_ms_mean);
    for (const ControlFrame& f : fixed.frames)
        EXPECT_EQ(f.e1_deg, 5.0);
    EXPECT_DOUBLE_EQ(fixed.summary.e1_deg_mean, 5.0);
}

// Counts the frames on which another policy beats the oracle by more than rel_tolerance, and
// reports the first few.
void expectOracleIsTheLimit(const ControlRun& oracle, const std::vector<const ControlRun*>& others,
                            double rel_tolerance) {
    for (const ControlRun* other_run : others) {
        const ControlRun& other = *other_run;
        const std::string& name = other.policy;
        ASSERT_EQ(other.frames.size(), oracle.frames.size());
        EXPECT_LE(oracle.summary.frame_ms_mean, other.summary.frame_ms_mean) << name;
        int beaten = 0;
        for (size_t i = 0; i < oracle.frames.size(); ++i) {
            const double o = oracle.frames[i].frameMs();
            const double p = other.frames[i].frameMs();
            if (o > p * (1.0 + rel_tolerance) + 1e-9 && ++beaten <= 5) {
                ADD_FAILURE() << name << " beats the oracle at frame " << i << ": " << p
                              << " ms at e1 " << other.frames[i].e1_deg << " vs " << o
                              << " ms at e1 " << oracle.frames[i].e1_deg;
            }
        }
        EXPECT_EQ(beaten, 0) << name;
    }
}

// T_remote is not smooth in e1: whole-pixel rectangles make it jump by ~0.2% every few
// hundredths of a degree. The oracle therefore refines its 1° grid with 0.1° and 0.01° scans
// rather than a bracket search, which settled in local dips and lost by up to 0.6%.
TEST_F(SyntheticDefault, IsTheLimitOnEveryFrameWithinOnePercentWhenOracleRuns) {
    expectOracleIsTheLimit(runs().oracle, {&runs().liwc, &runs().sw, &runs().fixed}, 0.01);
}

// Found by this suite with a golden-section oracle: frame 17, sw at e1 11.9° gave 2.2540 ms,
// the oracle's 11.758° 2.2668 ms (+0.57%). The finer scans hold the limit to 0.1%.
TEST_F(SyntheticDefault, IsTheLimitOnEveryFrameWhenOracleRuns) {
    expectOracleIsTheLimit(runs().oracle, {&runs().liwc, &runs().sw, &runs().fixed}, 1e-3);
}

TEST(PaperSuite, BalancesAndWidensFoveaOnSlowerLinkWhenLiwcRuns) {
    int balanced_lte = 0, balanced_5g = 0;
    for (SyntheticSpec spec : paperSyntheticSuite()) {
        spec.frames = 200;
        const WorkloadTrace trace = generateSyntheticWorkload(spec);
        const CostModel lte(trace.header, GpuModel{}, kLteBps);
        const CostModel fast(trace.header, GpuModel{}, k5gBps);
        const ControlRun on_lte = runNamed("liwc", trace, lte);
        const ControlRun on_5g = runNamed("liwc", trace, fast);
        if (on_lte.summary.frames_to_balance && *on_lte.summary.frames_to_balance <= 30)
            ++balanced_lte;
        if (on_5g.summary.frames_to_balance && *on_5g.summary.frames_to_balance <= 30)
            ++balanced_5g;
        // A slower link moves work to the headset: a larger fovea.
        EXPECT_GT(on_lte.summary.e1_deg_mean, on_5g.summary.e1_deg_mean) << spec.name;
    }
    EXPECT_GE(balanced_lte, 3);
    EXPECT_GE(balanced_5g, 3);
}

}  // namespace
}  // namespace qvr
