// The one percentile (nearest rank, core/run_summary.h) on small samples in closed form, and the
// run summary over frame samples: the start-up left out, means, FPS of scan-out.
#include "qvr/core/run_summary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace qvr {
namespace {

TEST(Percentile, NearestRankOnSmallSamples) {
    // Rank ceil(p/100 · n) of the sorted sample, 1-based.
    const std::vector<double> five = {50, 10, 40, 20, 30};  // sorted 10 20 30 40 50
    EXPECT_EQ(percentile(five, 100.0), 50.0);
    EXPECT_EQ(percentile(five, 99.0), 50.0);  // ceil(4.95) = 5
    EXPECT_EQ(percentile(five, 80.0), 40.0);  // ceil(4) = 4: no interpolation towards 50
    EXPECT_EQ(percentile(five, 50.0), 30.0);  // ceil(2.5) = 3
    EXPECT_EQ(percentile(five, 40.0), 20.0);  // ceil(2) = 2
    EXPECT_EQ(percentile(five, 20.0), 10.0);
    EXPECT_EQ(percentile(five, 1.0), 10.0);  // rank at least 1
    // An even count's median is the lower middle value, not the mean of the two.
    EXPECT_EQ(percentile({4, 1, 3, 2}, 50.0), 2.0);
    // p99 of 100 values is the 99th, of 101 the 100th, of 150 the 149th (the second-worst).
    std::vector<double> v;
    for (int i = 1; i <= 150; ++i)
        v.push_back(i);
    EXPECT_EQ(percentile(v, 99.0), 149.0);
    v.resize(101);
    EXPECT_EQ(percentile(v, 99.0), 100.0);
    v.resize(100);
    EXPECT_EQ(percentile(v, 99.0), 99.0);
    EXPECT_EQ(percentile({7.5}, 99.0), 7.5);
    EXPECT_EQ(percentile({}, 99.0), 0.0);
}

std::vector<FrameSample> steadyFrames(int n) {
    std::vector<FrameSample> v(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        FrameSample& f = v[static_cast<size_t>(i)];
        f.pose_ms = 10.0 * i;
        f.display_ms = 10.0 * i + 25.0;
        f.mtp_ms = 20.0 + i;
        f.bytes = 1000.0 * i;
        f.e1_deg = i % 2 ? 10.0 : 20.0;
        f.t_local_ms = 5.0;
        f.t_remote_ms = 30.0;
        f.remote_requested = i % 2 == 0;
        f.headset_busy_ms = i == 0 ? 0.0 : 8.0;
        f.reused = i == 3;
    }
    return v;
}

TEST(FrameSummarizer, MeansP99AndScanOutRate) {
    const RunStats s = summarizeFrames(steadyFrames(10), 0);
    EXPECT_EQ(s.frames, 10);
    EXPECT_EQ(s.frames_displayed, 10);
    EXPECT_EQ(s.frames_reused, 1);
    EXPECT_DOUBLE_EQ(s.fps_mean, 100.0);    // a display every 10 ms
    EXPECT_DOUBLE_EQ(s.mtp_ms_mean, 24.5);  // 20…29
    EXPECT_DOUBLE_EQ(s.mtp_ms_p99, 29.0);   // nearest rank of ten: the worst
    EXPECT_DOUBLE_EQ(s.bytes_per_frame_mean, 4500.0);
    EXPECT_DOUBLE_EQ(s.e1_deg_mean, 15.0);
    EXPECT_DOUBLE_EQ(s.t_remote_ms_mean, 30.0);  // over the five that asked
    EXPECT_EQ(s.headset_busy_frames, 9);
    EXPECT_DOUBLE_EQ(s.headset_busy_ms_mean, 8.0);
    EXPECT_DOUBLE_EQ(s.wall_s, (90.0 + 25.0) * 1e-3);
    EXPECT_EQ(summarizeFrames({}, 3).frames, 0);
}

TEST(FrameSummarizer, TheStartUpLastsUntilRemoteLayersAreShown) {
    auto v = steadyFrames(20);
    for (size_t i = 0; i < v.size(); ++i) {
        v[i].remote_requested = true;
        v[i].remote_shown = i >= 7;
    }
    const RunStats s = summarizeFrames(v, 2);
    EXPECT_EQ(s.warmup_frames, 7);
    EXPECT_EQ(s.frames, 13);
    EXPECT_DOUBLE_EQ(s.startup_mtp_ms_max, 26.0);
    EXPECT_DOUBLE_EQ(s.mtp_ms_p99, 39.0);
    EXPECT_FALSE(s.startup_unfinished);
    for (FrameSample& f : v)
        f.remote_shown = false;
    const RunStats never = summarizeFrames(v, 2);
    EXPECT_TRUE(never.startup_unfinished);
    EXPECT_EQ(never.frames, 20);
}

// A late frame that shows an older frame's layers for the first time puts new content on
// screen; re-warping the same layers again does not. A design whose layers stopped after its
// start-up showed none new in its counted frames, whatever its frame rate (seed 2027 c13's
// fixed:2: 55.7 FPS, 100 of 100 frames reused).
TEST(FrameSummarizer, CountsTheFramesThatShowedNewLayers) {
    auto v = steadyFrames(12);
    const int64_t shown[12] = {-1, 0, 1, 1, 3, 3, 3, 6, 5, 8, 9, 9};
    for (size_t i = 0; i < v.size(); ++i) {
        v[i].remote_requested = true;
        v[i].shown_frame = shown[i];
        v[i].remote_shown = shown[i] >= 0;
    }
    const RunStats s = summarizeFrames(v, 2);  // frames 2…11 counted
    EXPECT_EQ(s.frames, 10);
    EXPECT_EQ(s.frames_remote_requested, 10);
    // New: 1 (frame 1 showed 0), 3, 6, 8, 9; not: 1, 3, 3 again, and 5 after 6.
    EXPECT_EQ(s.frames_new_layers, 5);
    // Layers stopped at frame 1's: nothing new after the start-up.
    for (size_t i = 1; i < v.size(); ++i)
        v[i].shown_frame = 0;
    const RunStats stale = summarizeFrames(v, 2);
    EXPECT_EQ(stale.frames_new_layers, 0);
    EXPECT_EQ(stale.frames_remote_requested, 10);
}

TEST(FrameSummarizer, KeepsAsManyMtpsExactAsItIsTold) {
    // Beyond exact_mtp_frames the p99 is the histogram's; a caller that asks for every frame gets
    // the nearest rank itself.
    std::vector<FrameSample> v = steadyFrames(200);
    std::vector<double> mtp;
    for (size_t i = 0; i < v.size(); ++i) {
        v[i].mtp_ms = 10.0 + std::fmod(7.3 * static_cast<double>(i), 13.0);
        mtp.push_back(v[i].mtp_ms);
    }
    auto p99 = [&](size_t exact_mtp_frames) {
        FrameSummarizer s(0, exact_mtp_frames);
        for (const FrameSample& f : v)
            s.add(f);
        return s.finish().mtp_ms_p99;
    };
    EXPECT_EQ(p99(v.size()), percentile(mtp, 99.0));
    EXPECT_NE(p99(50), percentile(mtp, 99.0));
    EXPECT_NEAR(p99(50), percentile(mtp, 99.0), percentile(mtp, 99.0) * 1e-3);
}

}  // namespace
}  // namespace qvr
