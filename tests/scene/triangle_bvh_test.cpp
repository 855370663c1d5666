// Triangle counting for LIWC: the BVH gives exactly the brute-force counts on random cones and
// views, the ring histogram is consistent with the cone count, and hand-placed triangles land
// where geometry says.
#include "qvr/scene/triangle_bvh.h"

#include <cmath>
#include <numeric>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "qvr/core/pose.h"
#include "qvr/scene/builtin_scene.h"
#include "qvr/scene/scene_loader.h"

namespace qvr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Triangles of mixed sizes scattered through a 20 m cube, some of them huge.
struct Soup {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
};
Soup randomSoup(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-10.0f, 10.0f);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::uniform_real_distribution<float> logsize(-3.0f, 1.3f);
    Soup s;
    for (int i = 0; i < n; ++i) {
        const glm::vec3 c(pos(rng), pos(rng), pos(rng));
        const float size = std::pow(10.0f, logsize(rng));
        for (int k = 0; k < 3; ++k) {
            s.positions.push_back(c + size * glm::vec3(unit(rng), unit(rng), unit(rng)));
            s.indices.push_back(static_cast<uint32_t>(s.positions.size() - 1));
        }
    }
    return s;
}

glm::dvec3 randomDirection(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    glm::dvec3 d;
    do {
        d = glm::dvec3(n(rng), n(rng), n(rng));
    } while (glm::length(d) < 1e-3);
    return glm::normalize(d);
}

glm::dquat randomOrientation(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    return glm::normalize(glm::dquat(n(rng), n(rng), n(rng), n(rng)));
}

EyeView randomView(std::mt19937& rng) {
    std::uniform_real_distribution<double> pos(-8.0, 8.0);
    std::uniform_real_distribution<double> tan(0.3, 1.6);
    EyeView v;
    v.position_m = {pos(rng), pos(rng), pos(rng)};
    v.orientation = randomOrientation(rng);
    v.tan_left = tan(rng);
    v.tan_right = tan(rng);
    v.tan_down = tan(rng);
    v.tan_up = tan(rng);
    std::uniform_real_distribution<double> nearf(0.01, 1.0);
    v.near_m = nearf(rng);
    v.far_m = v.near_m + std::uniform_real_distribution<double>(2.0, 40.0)(rng);
    return v;
}

// A gaze inside the frustum (tangent space), as the eye tracker would report.
glm::dvec3 randomGaze(const EyeView& v, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double x = -v.tan_left + u(rng) * (v.tan_left + v.tan_right);
    const double y = -v.tan_down + u(rng) * (v.tan_down + v.tan_up);
    return glm::normalize(glm::dvec3(x, y, -1.0));
}

TEST(TriangleBvh, ConeCountsEqualBruteForceOnRandomCones) {
    const Soup s = randomSoup(20000, 1);
    const TriangleBvh bvh(s.positions, s.indices);
    EXPECT_EQ(bvh.triangleCount(), 20000u);
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> pos(-12.0, 12.0);
    std::uniform_real_distribution<double> angle(0.5, 70.0);
    uint64_t total = 0;
    for (int i = 0; i < 150; ++i) {
        ViewCone c;
        c.apex_m = {pos(rng), pos(rng), pos(rng)};
        c.direction = randomDirection(rng) * 3.0;  // need not be unit
        c.half_angle_deg = angle(rng);
        if (i % 3 == 1)
            c.near_m = 0.5;
        if (i % 3 == 2) {
            c.near_m = 1.0;
            c.far_m = 8.0;
        }
        const uint64_t fast = bvh.countTrianglesInCone(c);
        EXPECT_EQ(fast, bvh.countTrianglesInConeBruteForce(c)) << "cone " << i;
        total += fast;
    }
    EXPECT_GT(total, 1000u);  // the cones do hit things
}

TEST(TriangleBvh, FrustumAndRingCountsEqualBruteForceOnRandomViews) {
    const Soup s = randomSoup(20000, 3);
    const TriangleBvh bvh(s.positions, s.indices);
    std::mt19937 rng(4);
    uint64_t total = 0;
    for (int i = 0; i < 60; ++i) {
        const EyeView v = randomView(rng);
        const glm::dvec3 gaze = randomGaze(v, rng);
        const double ring_deg = i % 2 ? 5.0 : 2.5;
        const int rings = 1 + i % 24;
        const auto fast = bvh.trianglesPerRing(v, gaze, ring_deg, rings);
        const auto slow = bvh.trianglesPerRingBruteForce(v, gaze, ring_deg, rings);
        EXPECT_EQ(fast, slow) << "view " << i;
        const uint64_t in_frustum = bvh.countTrianglesInFrustum(v);
        EXPECT_EQ(in_frustum, bvh.countTrianglesInFrustumBruteForce(v));
        EXPECT_EQ(in_frustum, std::accumulate(fast.begin(), fast.end(), uint64_t{0}));
        total += in_frustum;
    }
    EXPECT_GT(total, 1000u);
}

TEST(TriangleBvh, RingPrefixSumsEqualConeCountsWhenTheConeFitsTheFrustum) {
    const Soup s = randomSoup(20000, 5);
    const TriangleBvh bvh(s.positions, s.indices);
    std::mt19937 rng(6);
    for (int i = 0; i < 10; ++i) {
        // A wide frustum (±60°) and the gaze on its axis: cones up to 55° stay inside it, so
        // frustum ∩ cone = cone between the near and far planes.
        EyeView v = randomView(rng);
        v.tan_left = v.tan_right = v.tan_down = v.tan_up = std::tan(60.0 * kPi / 180.0);
        const glm::dvec3 gaze_eye(0, 0, -1);
        const auto rings = bvh.trianglesPerRing(v, gaze_eye, 5.0, 12);
        uint64_t prefix = 0;
        for (int k = 0; k < 11; ++k) {
            prefix += rings[static_cast<size_t>(k)];
            ViewCone c;
            c.apex_m = v.position_m;
            c.direction = v.orientation * gaze_eye;
            c.half_angle_deg = 5.0 * (k + 1);
            c.near_m = v.near_m;
            c.far_m = v.far_m;
            EXPECT_EQ(prefix, bvh.countTrianglesInCone(c)) << "view " << i << " ring " << k;
        }
    }
}

// One small triangle centred on a direction at `ecc_deg` from the view axis, 10 m away.
TriangleBvh singleTriangleAt(double ecc_deg, double size_m, double distance_m = 10.0) {
    const double a = ecc_deg * kPi / 180.0;
    const glm::dvec3 d(std::sin(a), 0.0, -std::cos(a));
    const glm::dvec3 c = distance_m * d;
    const glm::dvec3 up(0, 1, 0);
    const glm::dvec3 side = glm::normalize(glm::cross(d, up));
    std::vector<glm::vec3> p = {glm::vec3(c + size_m * up),
                                glm::vec3(c - size_m * up + size_m * side),
                                glm::vec3(c - size_m * up - size_m * side)};
    return TriangleBvh(p, {0, 1, 2});
}

TEST(TriangleBvh, HandPlacedTrianglesLandInTheirRings) {
    const EyeView v = EyeView::symmetric({0, 0, 0}, glm::dquat(1, 0, 0, 0), 100, 110, 0.1, 100);
    const glm::dvec3 ahead(0, 0, -1);
    // Straight ahead: the gaze ray hits it, eccentricity 0.
    EXPECT_EQ(singleTriangleAt(0, 0.5).trianglesPerRing(v, ahead, 5, 10)[0], 1u);
    // A tiny triangle at 22° lies in ring 4 = [20°, 25°).
    auto r = singleTriangleAt(22, 0.01).trianglesPerRing(v, ahead, 5, 10);
    EXPECT_EQ(r[4], 1u);
    EXPECT_EQ(std::accumulate(r.begin(), r.end(), uint64_t{0}), 1u);
    // Its nearest point, not its centre, decides: centre at 22°, half-width ~5.7° → ring 3.
    r = singleTriangleAt(22, 1.0).trianglesPerRing(v, ahead, 5, 10);
    EXPECT_EQ(r[3], 1u);
    // Beyond the last ring it is counted in the last one.
    r = singleTriangleAt(45, 0.01).trianglesPerRing(v, ahead, 5, 4);
    EXPECT_EQ(r[3], 1u);
    // Outside the 100° horizontal field of view: not processed.
    EXPECT_EQ(singleTriangleAt(55, 0.01).countTrianglesInFrustum(v), 0u);
    // Behind the eye, or beyond the far plane.
    EXPECT_EQ(singleTriangleAt(180, 0.5).countTrianglesInFrustum(v), 0u);
    EXPECT_EQ(singleTriangleAt(0, 0.5, 150).countTrianglesInFrustum(v), 0u);
    // Gazing 22° right puts the small triangle in ring 0.
    const glm::dvec3 right(std::sin(22 * kPi / 180), 0, -std::cos(22 * kPi / 180));
    EXPECT_EQ(singleTriangleAt(22, 0.01).trianglesPerRing(v, right, 5, 10)[0], 1u);
    // Cone counts: within 21.9° no, within 22.1° yes.
    const TriangleBvh t = singleTriangleAt(22, 0.001);
    EXPECT_EQ(t.countTrianglesInCone({{0, 0, 0}, ahead, 21.9}), 0u);
    EXPECT_EQ(t.countTrianglesInCone({{0, 0, 0}, ahead, 22.1}), 1u);
}

TEST(TriangleBvh, ATriangleCrossingTheNearPlaneCounts) {
    // A large floor triangle under the eye reaching from behind to in front of it.
    std::vector<glm::vec3> p = {{-5, -1.6f, 5}, {5, -1.6f, 5}, {0, -1.6f, -20}};
    const TriangleBvh t(p, {0, 1, 2});
    const EyeView v = EyeView::symmetric({0, 0, 0}, glm::dquat(1, 0, 0, 0), 90, 90, 0.1, 100);
    EXPECT_EQ(t.countTrianglesInFrustum(v), 1u);
    // Looking straight up it is out of view.
    const EyeView up = EyeView::symmetric({0, 0, 0}, glm::angleAxis(kPi / 2, glm::dvec3(1, 0, 0)),
                                          90, 90, 0.1, 100);
    EXPECT_EQ(t.countTrianglesInFrustum(up), 0u);
}

TEST(TriangleBvh, OutcodeCountsBracketTheExactCountFromAbove) {
    // Beside the top-left corner of a 90°×90° frustum: no vertex set shares an outside plane,
    // yet the triangle misses the frustum.
    std::vector<glm::vec3> p = {{-30, 5, -10}, {-5, 30, -10}, {-30, 30, -10}};
    const TriangleBvh corner(p, {0, 1, 2});
    const EyeView v = EyeView::symmetric({0, 0, 0}, glm::dquat(1, 0, 0, 0), 90, 90, 0.1, 100);
    EXPECT_EQ(corner.countTrianglesInFrustum(v), 0u);
    EXPECT_EQ(corner.countTrianglesByOutcodes(v), 1u);
    // On random views the outcode count is never below the exact one.
    const Soup s = randomSoup(5000, 9);
    const TriangleBvh bvh(s.positions, s.indices);
    std::mt19937 rng(10);
    for (int i = 0; i < 20; ++i) {
        const EyeView rv = randomView(rng);
        EXPECT_GE(bvh.countTrianglesByOutcodes(rv), bvh.countTrianglesInFrustum(rv));
    }
}

TEST(TriangleBvh, BuiltinRoomCountsFromTheSpawnPoint) {
    const Scene scene = makeBuiltinRoom(64);
    const TriangleBvh bvh(scene);
    const SpawnPoint sp = scene.spawns[0];
    const glm::quat q = quatFromEulerDeg({sp.yaw_deg, -20.0, 0.0});
    const EyeView v =
        EyeView::symmetric(glm::dvec3(sp.position_m), glm::dquat(q), 100, 110, 0.05, 100);
    const glm::dvec3 gaze(0, 0, -1);
    const auto rings = bvh.trianglesPerRing(v, gaze, 5.0, 16);
    EXPECT_EQ(rings, bvh.trianglesPerRingBruteForce(v, gaze, 5.0, 16));
    const uint64_t in_view = std::accumulate(rings.begin(), rings.end(), uint64_t{0});
    EXPECT_GT(in_view, scene.triangleCount() / 4);  // looking across the board
    EXPECT_LT(in_view, scene.triangleCount());      // but not behind
    // Fovea cones grow monotonically and stay below the view.
    uint64_t last = 0;
    for (double e : {5.0, 10.0, 20.0, 40.0}) {
        ViewCone c{glm::dvec3(sp.position_m), v.orientation * gaze, e, 0.05, 100};
        const uint64_t n = bvh.countTrianglesInCone(c);
        EXPECT_GE(n, last);
        last = n;
    }
    EXPECT_GT(last, 0u);
}

// The BVH's saving is counted, not timed (timings belong to bench/scene_bench.cpp): on a scene of
// ~200 k triangles it answers the fovea cone and 18 rings exactly as brute force does while
// testing a small fraction of the triangles one by one.
TEST(TriangleBvh, TestsFewTrianglesOneByOneAndAgreesWithBruteForceOnALargeScene) {
    const Scene scene = makeBuiltinRoom(40);
    ASSERT_GT(scene.triangleCount(), 150'000u);
    const TriangleBvh bvh(scene);
    const SpawnPoint sp = scene.spawns[0];
    const EyeView v = EyeView::symmetric(glm::dvec3(sp.position_m),
                                         glm::dquat(quatFromEulerDeg({sp.yaw_deg, -25.0, 0.0})),
                                         100, 110, 0.05, 100);
    ViewCone fovea{glm::dvec3(sp.position_m), v.orientation * glm::dvec3(0, 0, -1), 10.0, 0.05,
                   100};
    BvhQueryStats cone_stats;
    BvhQueryStats ring_stats;
    const uint64_t fast = bvh.countTrianglesInCone(fovea, &cone_stats);
    const auto rings = bvh.trianglesPerRing(v, {0, 0, -1}, 5.0, 18, &ring_stats);
    EXPECT_EQ(fast, bvh.countTrianglesInConeBruteForce(fovea));
    EXPECT_EQ(rings, bvh.trianglesPerRingBruteForce(v, {0, 0, -1}, 5.0, 18));
    EXPECT_GT(fast, 0u);
    EXPECT_LT(cone_stats.triangles_tested, scene.triangleCount() / 10);
    EXPECT_LT(ring_stats.triangles_tested, scene.triangleCount() / 2);
    EXPECT_GT(cone_stats.nodes_accepted_whole + ring_stats.nodes_accepted_whole, 0u);
}

}  // namespace
}  // namespace qvr
