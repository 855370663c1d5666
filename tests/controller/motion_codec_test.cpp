// LIWC's motion codec (paper §4.1): one bit per head degree of freedom that changed, two bits per
// gaze axis (moved, and its sign), a 10-bit index; decodeMotion is its inverse.
#include "qvr/controller/motion_codec.h"

#include <random>

#include <gtest/gtest.h>

namespace qvr {
namespace {

Pose poseAt(const EulerDeg& e, glm::vec3 p = glm::vec3(0.0f, 1.7f, 0.0f)) {
    Pose pose;
    pose.orientation = quatFromEulerDeg(e);
    pose.position_m = p;
    return pose;
}

constexpr uint16_t bit(int i) {
    return static_cast<uint16_t>(1u << i);
}

TEST(EncodeMotion, IsZeroWhenNothingMoves) {
    const Pose p = poseAt({20.0, -10.0, 3.0});
    EXPECT_EQ(encodeMotion(p, p, {4, 5}, {4, 5}), 0);
}

TEST(EncodeMotion, SetsOnlyTheBitOfEachHeadDofWhenItAloneChanges) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> ang(-60.0, 60.0);
    for (int trial = 0; trial < 50; ++trial) {
        const EulerDeg e{ang(rng) * 2.0, ang(rng), ang(rng)};
        const glm::vec3 pos(0.1f, 1.6f, -0.2f);
        const Pose a = poseAt(e, pos);
        for (double step : {1.0, -1.0, 0.4, -0.4}) {
            EXPECT_EQ(
                encodeMotion(a, poseAt({e.yaw_deg + step, e.pitch_deg, e.roll_deg}, pos), {}, {}),
                bit(0));
            EXPECT_EQ(
                encodeMotion(a, poseAt({e.yaw_deg, e.pitch_deg + step, e.roll_deg}, pos), {}, {}),
                bit(1));
            EXPECT_EQ(
                encodeMotion(a, poseAt({e.yaw_deg, e.pitch_deg, e.roll_deg + step}, pos), {}, {}),
                bit(2));
        }
        const float d = 0.01f;
        EXPECT_EQ(encodeMotion(a, poseAt(e, pos + glm::vec3(d, 0, 0)), {}, {}), bit(3));
        EXPECT_EQ(encodeMotion(a, poseAt(e, pos + glm::vec3(0, -d, 0)), {}, {}), bit(4));
        EXPECT_EQ(encodeMotion(a, poseAt(e, pos + glm::vec3(0, 0, d)), {}, {}), bit(5));
    }
}

TEST(EncodeMotion, SetsGazeBitsWithSignWhenGazeMoves) {
    const Pose p = poseAt({0, 0, 0});
    const Gaze g0{2.0, -3.0};
    EXPECT_EQ(encodeMotion(p, p, g0, {3.0, -3.0}), bit(6) | bit(7));  // right
    EXPECT_EQ(encodeMotion(p, p, g0, {1.0, -3.0}), bit(6));           // left: sign cleared
    EXPECT_EQ(encodeMotion(p, p, g0, {2.0, -2.0}), bit(8) | bit(9));  // up
    EXPECT_EQ(encodeMotion(p, p, g0, {2.0, -4.0}), bit(8));           // down
    EXPECT_EQ(encodeMotion(p, p, g0, {3.0, -4.0}), bit(6) | bit(7) | bit(8));
    EXPECT_EQ(encodeMotion(p, p, g0, {1.0, -2.0}), bit(6) | bit(8) | bit(9));
    // Below the threshold the axis did not move and its sign bit stays clear.
    EXPECT_EQ(encodeMotion(p, p, g0, {2.4, -3.0}), 0);
    EXPECT_EQ(encodeMotion(p, p, g0, {2.0, -2.6}), 0);
    EXPECT_EQ(encodeMotion(p, p, g0, {2.4, -4.0}), bit(8));
}

TEST(EncodeMotion, RespectsThresholdsWhenChangesAreNearThem) {
    const MotionThresholds t;  // 0.25°, 2 mm, 0.5°
    const Pose a = poseAt({10, 5, 0});
    EXPECT_EQ(encodeMotion(a, poseAt({10.2, 5, 0}), {}, {}, t), 0);
    EXPECT_EQ(encodeMotion(a, poseAt({10.3, 5, 0}), {}, {}, t), bit(0));
    EXPECT_EQ(encodeMotion(a, poseAt({10, 5, 0}, {0.0015f, 1.7f, 0}), {}, {}, t), 0);
    EXPECT_EQ(encodeMotion(a, poseAt({10, 5, 0}, {0.0025f, 1.7f, 0}), {}, {}, t), bit(3));
    EXPECT_EQ(encodeMotion(a, a, {0, 0}, {0.45, 0}, t), 0);
    EXPECT_EQ(encodeMotion(a, a, {0, 0}, {0.55, 0}, t), bit(6) | bit(7));
    // Custom thresholds move the boundaries.
    MotionThresholds coarse;
    coarse.rotation_deg = 2.0;
    coarse.translation_m = 0.05;
    coarse.gaze_deg = 3.0;
    EXPECT_EQ(encodeMotion(a, poseAt({11.5, 6.5, 1.5}, {0.04f, 1.74f, 0.04f}), {0, 0}, {2.5, -2.5},
                           coarse),
              0);
    EXPECT_EQ(encodeMotion(a, poseAt({12.5, 5, 0}), {0, 0}, {0, -3.5}, coarse), bit(0) | bit(8));
}

TEST(EncodeMotion, WrapsYawWhenCrossingHalfTurn) {
    EXPECT_EQ(encodeMotion(poseAt({179.0, 0, 0}), poseAt({-179.0, 0, 0}), {}, {}), bit(0));
    EXPECT_EQ(encodeMotion(poseAt({179.9, 0, 0}), poseAt({-179.95, 0, 0}), {}, {}), 0);
    EXPECT_EQ(encodeMotion(poseAt({0, 0, -179.9}), poseAt({0, 0, 179.9}), {}, {}), 0);
}

TEST(EncodeMotion, StaysBelow1024AndDecodesToSameFieldsWhenMotionIsRandom) {
    std::mt19937 rng(77);
    std::uniform_real_distribution<double> ang(-80.0, 80.0);
    std::uniform_real_distribution<double> step(-1.0, 1.0);
    std::uniform_real_distribution<float> pos(-0.004f, 0.004f);
    const MotionThresholds t;
    for (int i = 0; i < 5000; ++i) {
        const EulerDeg e{2.0 * ang(rng), ang(rng), ang(rng)};
        const EulerDeg e2{e.yaw_deg + step(rng), e.pitch_deg + step(rng), e.roll_deg + step(rng)};
        const glm::vec3 p0(0.0f, 1.7f, 0.0f);
        const glm::vec3 dp(pos(rng), pos(rng), pos(rng));
        const Gaze g0{ang(rng) / 4, ang(rng) / 4};
        const Gaze g1{g0.x_deg + step(rng), g0.y_deg + step(rng)};
        const uint16_t code = encodeMotion(poseAt(e, p0), poseAt(e2, p0 + dp), g0, g1, t);
        ASSERT_LT(code, kMotionCodes);
        const MotionFields f = decodeMotion(code);
        // Position and gaze bits are easy to predict exactly; stay away from the thresholds.
        const glm::vec3 moved = (p0 + dp) - p0;
        if (std::fabs(std::fabs(moved.x) - 0.002f) > 1e-5f) {
            EXPECT_EQ(f.x, std::fabs(moved.x) > 0.002f);
        }
        if (std::fabs(std::fabs(moved.y) - 0.002f) > 1e-5f) {
            EXPECT_EQ(f.y, std::fabs(moved.y) > 0.002f);
        }
        if (std::fabs(std::fabs(moved.z) - 0.002f) > 1e-5f) {
            EXPECT_EQ(f.z, std::fabs(moved.z) > 0.002f);
        }
        const double gx = g1.x_deg - g0.x_deg, gy = g1.y_deg - g0.y_deg;
        EXPECT_EQ(f.gaze_h, std::fabs(gx) > 0.5);
        EXPECT_EQ(f.gaze_right, std::fabs(gx) > 0.5 && gx > 0);
        EXPECT_EQ(f.gaze_v, std::fabs(gy) > 0.5);
        EXPECT_EQ(f.gaze_up, std::fabs(gy) > 0.5 && gy > 0);
        // A sign bit never appears without its axis.
        EXPECT_TRUE(f.gaze_h || !f.gaze_right);
        EXPECT_TRUE(f.gaze_v || !f.gaze_up);
    }
}

TEST(DecodeMotion, InvertsBitLayoutWhenGivenEveryCode) {
    for (int code = 0; code < kMotionCodes; ++code) {
        const MotionFields f = decodeMotion(static_cast<uint16_t>(code));
        auto has = [code](int i) { return ((code >> i) & 1) != 0; };
        EXPECT_EQ(f.yaw, has(0)) << code;
        EXPECT_EQ(f.pitch, has(1)) << code;
        EXPECT_EQ(f.roll, has(2)) << code;
        EXPECT_EQ(f.x, has(3)) << code;
        EXPECT_EQ(f.y, has(4)) << code;
        EXPECT_EQ(f.z, has(5)) << code;
        EXPECT_EQ(f.gaze_h, has(6)) << code;
        EXPECT_EQ(f.gaze_right, has(7)) << code;
        EXPECT_EQ(f.gaze_v, has(8)) << code;
        EXPECT_EQ(f.gaze_up, has(9)) << code;
    }
    EXPECT_EQ(kMotionBits, 10);
    EXPECT_EQ(kMotionCodes, 1024);
}

}  // namespace
}  // namespace qvr
