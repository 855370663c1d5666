// The run summary, all at once and one frame at a time (telemetry.h RunSummarizer).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "qvr/runtime/telemetry.h"

namespace qvr::runtime {
namespace {

std::vector<FrameTelemetry> frames(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::lognormal_distribution<double> mtp(std::log(60.0), 0.4);
    std::vector<FrameTelemetry> v(n);
    for (size_t i = 0; i < n; ++i) {
        FrameTelemetry& t = v[i];
        t.frame = static_cast<int64_t>(i);
        t.pose_ns = static_cast<int64_t>(i) * 11'111'111;
        t.mtp_ms = mtp(rng);
        t.display_ns = i % 17 == 5 ? -1 : t.pose_ns + static_cast<int64_t>(t.mtp_ms * 1e6);
        t.reused = i % 13 == 0;
        t.fallback_local = i % 29 == 0;
        t.bytes = static_cast<int64_t>(1000 + i % 500);
        t.e1_deg = 5.0 + double(i % 7);
        t.t_local_ms = 10.0 + double(i % 5);
        t.remote_requested = i % 3 != 0;
        t.shown_frame = t.remote_requested ? static_cast<int64_t>(i) : -1;
        t.t_remote_ms = 30.0 + double(i % 11);
        t.uca_ms = 2.0;
    }
    return v;
}

// The nearest-rank percentile summarizeRun used before it streamed, over frames[skip…].
double exactP99(const std::vector<FrameTelemetry>& v, size_t skip) {
    std::vector<double> m;
    for (size_t i = skip; i < v.size(); ++i)
        m.push_back(v[i].mtp_ms);
    return percentile(m, 99.0);
}

TEST(RunSummarizer, LeavesOutTheStartUpUnlessTheRunIsNoLonger) {
    const auto v = frames(30, 1);
    const DesignSummary s = summarizeRun("qvr", v, 10);
    EXPECT_EQ(s.warmup_frames, 10);
    EXPECT_EQ(s.frames, 20);
    double worst = 0.0, mean = 0.0;
    for (size_t i = 0; i < 10; ++i)
        worst = std::max(worst, v[i].mtp_ms);
    for (size_t i = 10; i < 30; ++i)
        mean += v[i].mtp_ms / 20.0;
    EXPECT_DOUBLE_EQ(s.startup_mtp_ms_max, worst);
    EXPECT_NEAR(s.mtp_ms_mean, mean, 1e-9);
    EXPECT_DOUBLE_EQ(s.mtp_ms_p99, exactP99(v, 10));
    // Ten frames of a ten-frame warm-up: all of them are the summary.
    const std::vector<FrameTelemetry> ten(v.begin(), v.begin() + 10);
    const DesignSummary t = summarizeRun("qvr", ten, 10);
    EXPECT_EQ(t.frames, 10);
    EXPECT_EQ(t.warmup_frames, 0);
    EXPECT_DOUBLE_EQ(t.mtp_ms_p99, exactP99(ten, 0));
}

TEST(RunSummarizer, TheStartUpLastsUntilTheServersFirstLayersAreOnScreen) {
    // Every frame asks for layers; none is on screen before frame 23 (the server's first frame
    // took longer than the wait limit and the headset re-warped nothing): frames 0–22 are the
    // start-up, not only the first ten.
    auto v = frames(40, 2);
    for (size_t i = 0; i < v.size(); ++i) {
        v[i].remote_requested = true;
        v[i].shown_frame = i < 23 ? -1 : static_cast<int64_t>(i) - 3;
        v[i].headset_busy_ms = 20.0 + double(i % 3);
    }
    const DesignSummary s = summarizeRun("remote", v, 10);
    EXPECT_EQ(s.warmup_frames, 23);
    EXPECT_EQ(s.frames, 17);
    EXPECT_FALSE(s.startup_unfinished);
    // The headset's busy time over the same frames as every other statistic.
    double busy = 0.0;
    for (size_t i = 23; i < 40; ++i)
        busy += v[i].headset_busy_ms / 17.0;
    EXPECT_EQ(s.headset_busy_frames, 17);
    EXPECT_NEAR(s.headset_busy_ms_mean, busy, 1e-9);
    double mean = 0.0;
    for (size_t i = 23; i < 40; ++i)
        mean += v[i].mtp_ms / 17.0;
    EXPECT_NEAR(s.mtp_ms_mean, mean, 1e-9);
    // A design that asks for nothing (local) keeps the ten frames.
    auto local = v;
    for (FrameTelemetry& t : local)
        t.remote_requested = false;
    EXPECT_EQ(summarizeRun("local", local, 10).warmup_frames, 10);
    // Without a warm-up every frame counts, shown or not.
    EXPECT_EQ(summarizeRun("remote", v, 0).frames, 40);
    // Layers never on screen: the start-up is the whole run, summarized whole.
    for (FrameTelemetry& t : v)
        t.shown_frame = -1;
    const DesignSummary never = summarizeRun("remote", v, 10);
    EXPECT_EQ(never.frames, 40);
    EXPECT_EQ(never.warmup_frames, 0);
    EXPECT_TRUE(never.startup_unfinished);  // and says so (qvr run warns)
    EXPECT_FALSE(summarizeRun("local", local, 10).startup_unfinished);
}

TEST(RunSummarizer, AHourLongSessionKeepsItsP99WithinTheHistogramsPrecision) {
    // More frames than kept exactly: the p99 comes from the histogram, every mean stays exact.
    const size_t n = FrameSummarizer::kExactMtpFrames * 3 + 123;
    const auto v = frames(n, 2);
    const DesignSummary s = summarizeRun("qvr", v, 10);
    EXPECT_EQ(s.frames, static_cast<int>(n - 10));
    const double exact = exactP99(v, 10);
    EXPECT_NEAR(s.mtp_ms_p99, exact, exact * 1e-3);
    EXPECT_NE(s.mtp_ms_p99, exact);  // it really is the histogram's answer
    int displayed = 0, reused = 0;
    for (size_t i = 10; i < n; ++i) {
        displayed += v[i].display_ns >= 0;
        reused += v[i].reused;
    }
    EXPECT_EQ(s.frames_displayed, displayed);
    EXPECT_EQ(s.frames_reused, reused);
}

TEST(RunSummarizer, OneFrameAtATimeEqualsTheWholeRun) {
    const auto v = frames(500, 3);
    RunSummarizer r("ffr", 10);
    for (const FrameTelemetry& t : v)
        r.add(t);
    const DesignSummary a = r.finish();
    const DesignSummary b = summarizeRun("ffr", v, 10);
    EXPECT_EQ(a.frames, b.frames);
    EXPECT_DOUBLE_EQ(a.fps_mean, b.fps_mean);
    EXPECT_DOUBLE_EQ(a.mtp_ms_p99, b.mtp_ms_p99);
    EXPECT_DOUBLE_EQ(a.t_remote_ms_mean, b.t_remote_ms_mean);
    EXPECT_DOUBLE_EQ(a.wall_s, b.wall_s);
    EXPECT_EQ(summarizeRun("x", {}, 10).frames, 0);
}

TEST(TelemetryCsv, TheFileIsTheHeaderAndOneRowAFrame) {
    const auto v = frames(3, 4);
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / "qvr_telemetry_test.csv";
    ASSERT_TRUE(writeTelemetryCsv(path.string(), "qvr", v));
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), telemetryCsvHeader() + telemetryCsvRow("qvr", v[0]) +
                              telemetryCsvRow("qvr", v[1]) + telemetryCsvRow("qvr", v[2]));
    EXPECT_FALSE(writeTelemetryCsv((path / "not_a_folder" / "x.csv").string(), "qvr", v));
}

}  // namespace
}  // namespace qvr::runtime
