#include "qvr/experiment/headsets.h"

#include <gtest/gtest.h>

#include <vector>

namespace qvr::experiment {
namespace {

TEST(Jain, EqualValuesAreFair) {
    const std::vector<double> fps = {30.0, 30.0, 30.0, 30.0};
    EXPECT_DOUBLE_EQ(jainFairness(fps), 1.0);
}

TEST(Jain, OneTakingAllIsOneOverN) {
    const std::vector<double> fps = {40.0, 0.0, 0.0, 0.0};
    EXPECT_DOUBLE_EQ(jainFairness(fps), 0.25);
}

TEST(Jain, KnownValue) {
    // (1 + 2 + 3)² / (3 · (1 + 4 + 9)) = 36 / 42.
    const std::vector<double> fps = {1.0, 2.0, 3.0};
    EXPECT_NEAR(jainFairness(fps), 36.0 / 42.0, 1e-12);
}

TEST(Jain, EmptyAndZeroAreFair) {
    EXPECT_DOUBLE_EQ(jainFairness({}), 1.0);
    const std::vector<double> zeros = {0.0, 0.0};
    EXPECT_DOUBLE_EQ(jainFairness(zeros), 1.0);
}

TEST(Jain, TenPercentSlowerHeadsetStaysAboveTheCriterion) {
    const std::vector<double> fps = {30.0, 30.0, 30.0, 27.0};
    EXPECT_GT(jainFairness(fps), 0.95);
    EXPECT_LT(jainFairness(fps), 1.0);
}

const std::vector<std::string> kRecordings = {"a.bvh", "b.bvh", "c.bvh"};

TEST(HeadsetWorkloads, HeadsetZeroIsThePlans) {
    const auto w = headsetWorkloads(1, "default", "model", 7, false, kRecordings);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0], (HeadsetWorkload{"default", "model", 7}));
}

TEST(HeadsetWorkloads, DefaultSetCyclesRecordingsAndSeeds) {
    const auto w = headsetWorkloads(5, "default", "model", 7, false, kRecordings);
    ASSERT_EQ(w.size(), 5u);
    EXPECT_EQ(w[0], (HeadsetWorkload{"default", "model", 7}));
    EXPECT_EQ(w[1], (HeadsetWorkload{"b.bvh", "model", 8}));
    EXPECT_EQ(w[2], (HeadsetWorkload{"c.bvh", "model", 9}));
    EXPECT_EQ(w[3], (HeadsetWorkload{"a.bvh", "model", 10}));
    EXPECT_EQ(w[4], (HeadsetWorkload{"b.bvh", "model", 11}));
}

TEST(HeadsetWorkloads, GivenMotionKeptWithOwnSeeds) {
    const auto w = headsetWorkloads(3, "walk.csv", "model", 1, false, kRecordings);
    for (size_t k = 0; k < w.size(); ++k)
        EXPECT_EQ(w[k], (HeadsetWorkload{"walk.csv", "model", 1 + k}));
}

TEST(HeadsetWorkloads, IdenticalAreAllThePlans) {
    const auto w = headsetWorkloads(4, "default", "model", 3, true, kRecordings);
    ASSERT_EQ(w.size(), 4u);
    for (const HeadsetWorkload& h : w)
        EXPECT_EQ(h, (HeadsetWorkload{"default", "model", 3}));
}

TEST(HeadsetWorkloads, HeadsetKPlaysKOffsetsAhead) {
    const auto w = headsetWorkloads(3, "default", "model", 3, true, kRecordings, 2.5);
    ASSERT_EQ(w.size(), 3u);
    for (size_t k = 0; k < w.size(); ++k)
        EXPECT_EQ(w[k], (HeadsetWorkload{"default", "model", 3, 2.5 * double(k)}));
}

runtime::ServerFrameStamps stamp(int64_t start_ns,
                                 std::vector<std::pair<int64_t, int64_t>> layers) {
    runtime::ServerFrameStamps s;
    s.start_ns = start_ns;
    for (const auto& [render_start, encode_end] : layers) {
        runtime::ServerFrameStamps::Layer l;
        l.render_start_ns = render_start;
        l.encode_end_ns = encode_end;
        s.layers.push_back(l);
    }
    return s;
}

TEST(ServerShare, CountsFramesInTheWindowAndTheirLayers) {
    const std::vector<runtime::ServerFrameStamps> stamps = {
        stamp(500, {{500, 1'000'500}}),                            // before the window
        stamp(1000, {{1000, 2'001'000}, {3'000'000, 4'000'000}}),  // 2 ms + 1 ms
        stamp(5000, {{5000, 4'005'000}}),                          // 4 ms
        stamp(9000, {{9000, 9000 + 50'000'000}}),                  // after the window
    };
    const ServerShare s = serverShare(stamps, 1000, 8000);
    EXPECT_EQ(s.frames, 2);
    EXPECT_NEAR(s.busy_ms_total, 7.0, 1e-9);
    EXPECT_NEAR(s.msPerFrame(), 3.5, 1e-9);
    EXPECT_EQ(serverShare(stamps, 100'000, 200'000).frames, 0);
    EXPECT_DOUBLE_EQ(serverShare(stamps, 100'000, 200'000).msPerFrame(), 0.0);
}

HeadsetOutcome outcome(int index, double fps, std::string error = "") {
    HeadsetOutcome h;
    h.index = index;
    h.summary.fps_mean = fps;
    h.summary.mtp_ms_p99 = 10.0 * index;
    h.error = std::move(error);
    return h;
}

TEST(AggregateHeadsets, OrdersByIndexAndLeavesFailedOutOfFairness) {
    const HeadsetsResult r =
        aggregateHeadsets("qvr", {outcome(2, 20.0), outcome(0, 20.0), outcome(1, 0.0, "refused")},
                          ServerShare{10, 50.0});
    ASSERT_EQ(r.headsets.size(), 3u);
    EXPECT_EQ(r.headsets[0].index, 0);
    EXPECT_EQ(r.headsets[2].index, 2);
    EXPECT_DOUBLE_EQ(r.jain_fairness_fps, 1.0);  // the refused one is not a zero
    EXPECT_DOUBLE_EQ(r.fps_mean, 20.0);
    EXPECT_DOUBLE_EQ(r.fps_min, 20.0);
    ASSERT_TRUE(r.server_ms_per_headset_frame.has_value());
    EXPECT_DOUBLE_EQ(*r.server_ms_per_headset_frame, 5.0);
}

TEST(AggregateHeadsets, UnfairAndNoServerFrames) {
    const HeadsetsResult r =
        aggregateHeadsets("ffr", {outcome(0, 30.0), outcome(1, 10.0)}, ServerShare{});
    EXPECT_NEAR(r.jain_fairness_fps, 1600.0 / (2.0 * 1000.0), 1e-12);
    EXPECT_DOUBLE_EQ(r.fps_min, 10.0);
    EXPECT_FALSE(r.server_ms_per_headset_frame.has_value());
}

TEST(HeadsetsJson, HasTheListAndTheIndex) {
    const HeadsetsResult r =
        aggregateHeadsets("qvr", {outcome(0, 30.0), outcome(1, 0.0, "gone")}, std::nullopt);
    const nlohmann::json j = headsetsJson(r);
    ASSERT_EQ(j["headsets"].size(), 2u);
    for (const char* key : {"fps_mean", "mtp_ms_p99", "bytes_per_frame_mean", "e1_deg_mean"})
        EXPECT_TRUE(j["headsets"][0].contains(key)) << key;
    EXPECT_EQ(j["headsets"][1]["error"], "gone");
    EXPECT_FALSE(j["headsets"][1].contains("fps_mean"));
    EXPECT_TRUE(j["server_ms_per_headset_frame"].is_null());
    EXPECT_DOUBLE_EQ(j["jain_fairness_fps"].get<double>(), 1.0);
}

TEST(HeadlineHeadsets, QvrElseTheLast) {
    std::vector<HeadsetsResult> by_design(3);
    by_design[0].design = "local";
    by_design[1].design = "qvr";
    by_design[2].design = "ffr";
    EXPECT_EQ(headlineHeadsets(by_design)->design, "qvr");
    by_design[1].design = "sw";
    EXPECT_EQ(headlineHeadsets(by_design)->design, "ffr");
    EXPECT_EQ(headlineHeadsets({}), nullptr);
}

}  // namespace
}  // namespace qvr::experiment
