// Pose traces (paper §5): interpolation, resampling, placement, smoothing and the strict CSV
// reader on good and malformed files.
#include "qvr/trace/pose_trace.h"

#include <cmath>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace qvr {
namespace {

using ::testing::HasSubstr;

PoseTrace turningWalk(int n, double step_ms) {
    PoseTrace t;
    for (int i = 0; i < n; ++i) {
        PoseSample s;
        s.t_ms = i * step_ms;
        s.pose.orientation = quatFromEulerDeg({i * 2.0, std::sin(i * 0.1) * 10.0, 1.0});
        s.pose.position_m = {0.01f * static_cast<float>(i), 1.6f, -0.02f * static_cast<float>(i)};
        t.samples.push_back(s);
    }
    return t;
}

TEST(PoseTrace, InterpolatesBySlerpAndClampsOutside) {
    PoseTrace t;
    t.samples.push_back({0.0, {quatFromEulerDeg({0, 0, 0}), {0, 0, 0}}});
    t.samples.push_back({100.0, {quatFromEulerDeg({80, 0, 0}), {1, 2, 3}}});
    const Pose mid = poseAt(t, 25.0);
    EXPECT_NEAR(eulerDegFromQuat(mid.orientation).yaw_deg, 20.0, 1e-3);
    EXPECT_NEAR(mid.position_m.z, 0.75f, 1e-6f);
    EXPECT_NEAR(eulerDegFromQuat(poseAt(t, -10).orientation).yaw_deg, 0.0, 1e-3);
    EXPECT_NEAR(poseAt(t, 500).position_m.y, 2.0f, 1e-6f);
}

TEST(PoseTrace, ResamplesToTheDisplayRate) {
    const PoseTrace src = turningWalk(121, 1000.0 / 120.0);  // 1 s at 120 Hz
    auto r = resamplePoses(src, 90.0, 0);
    ASSERT_TRUE(r.ok()) << r.error();
    ASSERT_EQ(r->samples.size(), 91u);
    EXPECT_NEAR(r->samples[90].t_ms, 1000.0, 1e-9);
    // Sample 3 at 33.3 ms sits exactly on source sample 4.
    EXPECT_LT(angleBetweenDeg(r->samples[3].pose.orientation, src.samples[4].pose.orientation),
              0.05);
    EXPECT_FALSE(resamplePoses(src, 90.0, 92).ok());
    EXPECT_FALSE(resamplePoses(src, 0.0, 10).ok());
    EXPECT_FALSE(resamplePoses(PoseTrace{}, 90.0, 10).ok());
}

TEST(PoseTrace, PlacesAtASpawnPointAndYaw) {
    const PoseTrace src = turningWalk(10, 10.0);
    const PoseTrace placed = placePoses(src, {10.0f, 0.5f, -4.0f}, -90.0);
    const auto& p0 = placed.samples[0].pose;
    EXPECT_NEAR(p0.position_m.x, 10.0f, 1e-5f);
    EXPECT_NEAR(p0.position_m.y, 2.1f, 1e-5f);
    EXPECT_NEAR(p0.position_m.z, -4.0f, 1e-5f);
    EXPECT_NEAR(eulerDegFromQuat(p0.orientation).yaw_deg, -90.0, 1e-3);
    // Relative motion is preserved: distances and turn angles between samples.
    for (size_t i = 1; i < src.samples.size(); ++i) {
        EXPECT_NEAR(glm::length(placed.samples[i].pose.position_m - p0.position_m),
                    glm::length(src.samples[i].pose.position_m - src.samples[0].pose.position_m),
                    1e-5f);
        EXPECT_NEAR(
            angleBetweenDeg(placed.samples[i].pose.orientation, p0.orientation),
            angleBetweenDeg(src.samples[i].pose.orientation, src.samples[0].pose.orientation),
            1e-2);
    }
}

TEST(PoseTrace, SmoothingRemovesJitterButKeepsTheTurn) {
    PoseTrace t = turningWalk(200, 1000.0 / 120.0);
    for (size_t i = 0; i < t.samples.size(); ++i) {  // ±3° alternating jitter in yaw
        const double jitter = (i % 2 == 0) ? 3.0 : -3.0;
        t.samples[i].pose.orientation =
            glm::normalize(quatFromEulerDeg({jitter, 0, 0}) * t.samples[i].pose.orientation);
    }
    const PoseTrace s = smoothPoses(t, 10.0);
    double raw_step = 0, smooth_step = 0;
    for (size_t i = 50; i < 150; ++i) {
        raw_step +=
            angleBetweenDeg(t.samples[i - 1].pose.orientation, t.samples[i].pose.orientation);
        smooth_step +=
            angleBetweenDeg(s.samples[i - 1].pose.orientation, s.samples[i].pose.orientation);
    }
    EXPECT_LT(smooth_step, raw_step / 2.0);
    EXPECT_NEAR(smooth_step / 100.0, 2.0, 0.5);  // the 2° per sample turn survives
}

TEST(PoseCsv, RoundTrips) {
    const PoseTrace t = turningWalk(50, 11.1111);
    auto back = parsePoseCsv(poseTraceToCsv(t), "poses.csv");
    ASSERT_TRUE(back.ok()) << back.error();
    ASSERT_EQ(back->samples.size(), t.samples.size());
    for (size_t i = 0; i < t.samples.size(); ++i) {
        EXPECT_NEAR(back->samples[i].t_ms, t.samples[i].t_ms, 1e-6);
        EXPECT_LT(angleBetweenDeg(back->samples[i].pose.orientation, t.samples[i].pose.orientation),
                  1e-3);
        EXPECT_EQ(back->samples[i].pose.position_m, t.samples[i].pose.position_m);
    }
}

TEST(PoseCsv, RejectsMalformedFilesWithALineNumber) {
    const std::string h = "t_ms,qw,qx,qy,qz,x,y,z\n";
    const std::string ok = "0,1,0,0,0,0,1.6,0\n";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"", "empty file"},
        {"t_ms,qw,qx,qy,qz,x,y\n" + ok, "poses.csv:1: header must be"},
        {h, "no poses"},
        {h + ok + "11,1,0,0,0,0,1.6\n", "poses.csv:3: only 7 fields"},
        {h + ok + "11,1,0,0,0,0,1.6,0,9\n", "poses.csv:3: more than 8 fields"},
        {h + "0,1,0,0,0,0,abc,0\n", "poses.csv:2: field 7 'abc'"},
        {h + "0,1,0,0,0,0,inf,0\n", "poses.csv:2: field 7"},
        {h + ok + ok, "poses.csv:3: t_ms 0 does not increase"},
        {h + "0,2,0,0,0,0,1.6,0\n", "poses.csv:2: quaternion norm 2"},
        {h + "0,1,0,0,0,0,1e9,0\n", "poses.csv:2: position beyond"},
        {h + ok + "\n" + "11,1,0,0,0,0,1.6,0\n", "poses.csv:4: data after a blank line"},
    };
    for (const auto& [text, message] : cases) {
        auto r = parsePoseCsv(text, "poses.csv");
        ASSERT_FALSE(r.ok()) << text;
        EXPECT_THAT(r.error(), HasSubstr(message)) << text;
    }
    EXPECT_TRUE(parsePoseCsv(h + ok, "poses.csv").ok());
    EXPECT_FALSE(loadPoseCsv("/nonexistent/poses.csv").ok());
}

}  // namespace
}  // namespace qvr
