// Pose helpers: the Euler decomposition the motion codec and the trace files rely on, checked
// against rotation matrices built by hand and on random angles.
#include "qvr/core/pose.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

namespace qvr {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRad = kPi / 180.0;

double wrap180(double d) {
    d = std::fmod(d, 360.0);
    if (d > 180.0)
        d -= 360.0;
    if (d < -180.0)
        d += 360.0;
    return d;
}

// Rodrigues' rotation of v about the unit axis k by angle_deg, in double precision.
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& k, double angle_deg) {
    const double a = angle_deg * kRad;
    return v * std::cos(a) + glm::cross(k, v) * std::sin(a) +
           k * glm::dot(k, v) * (1.0 - std::cos(a));
}

// The documented convention: yaw about +y, pitch about +x, roll about −z, applied as
// yaw · pitch · roll (roll first to a vector).
glm::dvec3 applyEuler(const EulerDeg& e, glm::dvec3 v) {
    v = rotate(v, {0, 0, -1}, e.roll_deg);
    v = rotate(v, {1, 0, 0}, e.pitch_deg);
    return rotate(v, {0, 1, 0}, e.yaw_deg);
}

void expectNear(const glm::dvec3& a, const glm::vec3& b, double tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(QuatFromEulerDeg, RotatesAsDocumentedWhenAppliedToAxes) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> angle(-180.0, 180.0);
    const glm::dvec3 axes[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}, {0.3, -0.5, 0.8}};
    for (int i = 0; i < 200; ++i) {
        const EulerDeg e{angle(rng), angle(rng) / 2.0, angle(rng)};
        const glm::quat q = quatFromEulerDeg(e);
        for (const auto& v : axes)
            expectNear(applyEuler(e, v), q * glm::vec3(v), 1e-5);
    }
}

TEST(QuatFromEulerDeg, TurnsLeftUpAndClockwiseWhenAnglesArePositive) {
    // Positive yaw turns the view (−z) towards −x (left, about +y by the right-hand rule).
    const glm::vec3 fwd = quatFromEulerDeg({90.0, 0.0, 0.0}) * glm::vec3(0, 0, -1);
    EXPECT_NEAR(fwd.x, -1.0, 1e-6);
    // Positive pitch looks up.
    const glm::vec3 up_look = quatFromEulerDeg({0.0, 30.0, 0.0}) * glm::vec3(0, 0, -1);
    EXPECT_NEAR(up_look.y, std::sin(30.0 * kRad), 1e-6);
    // Positive roll about −z tips the up vector towards +x.
    const glm::vec3 up = quatFromEulerDeg({0.0, 0.0, 30.0}) * glm::vec3(0, 1, 0);
    EXPECT_NEAR(up.x, std::sin(30.0 * kRad), 1e-6);
}

TEST(EulerDegFromQuat, InvertsQuatFromEulerDegWhenPitchBelow85) {
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> yaw(-179.9, 179.9);
    std::uniform_real_distribution<double> pitch(-85.0, 85.0);
    for (int i = 0; i < 5000; ++i) {
        const EulerDeg e{yaw(rng), pitch(rng), yaw(rng)};
        const EulerDeg back = eulerDegFromQuat(quatFromEulerDeg(e));
        // Float quaternions: errors grow like 1/cos(pitch) near the pole.
        EXPECT_NEAR(wrap180(back.yaw_deg - e.yaw_deg), 0.0, 0.02)
            << e.yaw_deg << " " << e.pitch_deg;
        EXPECT_NEAR(back.pitch_deg, e.pitch_deg, 0.02) << e.yaw_deg << " " << e.pitch_deg;
        EXPECT_NEAR(wrap180(back.roll_deg - e.roll_deg), 0.0, 0.02)
            << e.yaw_deg << " " << e.pitch_deg << " " << e.roll_deg;
    }
}

TEST(EulerDegFromQuat, ReturnsSameRotationWhenGivenArbitraryQuaternion) {
    // Any orientation (also |pitch| near 90) decomposes into angles that rebuild it, and a
    // non-unit or negated quaternion means the same rotation.
    std::mt19937 rng(99);
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (int i = 0; i < 2000; ++i) {
        glm::quat q(n(rng), n(rng), n(rng), n(rng));
        const glm::quat unit = glm::normalize(q);
        const EulerDeg e = eulerDegFromQuat(q * 3.0f);
        EXPECT_LE(e.pitch_deg, 90.0);
        EXPECT_GE(e.pitch_deg, -90.0);
        const glm::quat rebuilt = quatFromEulerDeg(e);
        for (const glm::vec3 v : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)})
            expectNear(glm::dvec3(unit * v), rebuilt * v, 2e-4);
        const EulerDeg neg = eulerDegFromQuat(-unit);
        EXPECT_NEAR(neg.pitch_deg, e.pitch_deg, 1e-3);
    }
}

TEST(AngleBetweenDeg, ReturnsRotationAngleWhenAboutAnyAxis) {
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_real_distribution<double> angle(0.0, 180.0);
    for (int i = 0; i < 1000; ++i) {
        const glm::dvec3 axis = glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
        const glm::dvec3 axis2 = glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
        const double theta = angle(rng);
        const glm::quat base =
            glm::angleAxis(static_cast<float>(angle(rng) * kRad), glm::vec3(axis2));
        const glm::quat turn = glm::angleAxis(static_cast<float>(theta * kRad), glm::vec3(axis));
        const glm::quat a = base;
        const glm::quat b = turn * base;
        // acos near 0 loses precision in float: allow 0.05° there.
        EXPECT_NEAR(angleBetweenDeg(a, b), theta, 0.05) << theta;
        EXPECT_NEAR(angleBetweenDeg(b, a), angleBetweenDeg(a, b), 1e-9);
        // q and −q are the same orientation.
        EXPECT_NEAR(angleBetweenDeg(a, -b), angleBetweenDeg(a, b), 1e-6);
    }
}

TEST(AngleBetweenDeg, ResolvesSmallAnglesWhenOrientationsAreClose) {
    // The dot product is taken in float, so 2·acos(1 − 2^−23) ≈ 0.056° is the finest step it
    // can resolve; a 0.2° turn must still read as 0.2° within that step.
    const glm::quat a = quatFromEulerDeg({10.0, 5.0, 0.0});
    const glm::quat b = quatFromEulerDeg({10.2, 5.0, 0.0});
    EXPECT_NEAR(angleBetweenDeg(a, b), 0.2, 0.06);
}

TEST(AngleBetweenDeg, IsZeroWhenOrientationsAreEqualAndHalfTurnWhenOpposite) {
    const glm::quat q = quatFromEulerDeg({30.0, 20.0, 10.0});
    EXPECT_NEAR(angleBetweenDeg(q, q), 0.0, 0.05);
    EXPECT_NEAR(angleBetweenDeg(q, -q), 0.0, 0.05);
    EXPECT_NEAR(angleBetweenDeg(quatFromEulerDeg({0, 0, 0}), quatFromEulerDeg({180, 0, 0})), 180.0,
                1e-3);
    EXPECT_NEAR(angleBetweenDeg(quatFromEulerDeg({0, 0, 0}), quatFromEulerDeg({-45, 0, 0})), 45.0,
                1e-3);
}

}  // namespace
}  // namespace qvr
