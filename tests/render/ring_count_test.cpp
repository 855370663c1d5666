// The cone tests of the draw list (draw_list.h): boxInsideCone, which decides what a periphery
// layer's hole may skip, against a brute-force check of the box's points; and
// addTrianglesPerRing, LIWC's pre-render ring counts from the draw clusters, against
// selectDraws' totals and the scene part's per-triangle BVH counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "hand_made_scene.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/render/draw_list.h"
#include "render_test_util.h"
#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)
#include "qvr/scene/scene_loader.h"
#include "qvr/scene/triangle_bvh.h"
#endif

namespace qvr {
namespace {

constexpr double kPi = 3.14159265358979323846;

double angleToAxisRad(const glm::dvec3& p, const glm::dvec3& apex, const glm::dvec3& axis) {
    const glm::dvec3 v = p - apex;
    const double len = glm::length(v);
    if (len == 0.0)
        return 0.0;
    return std::acos(std::clamp(glm::dot(v, axis) / len, -1.0, 1.0));
}

TEST(BoxInsideCone, IsNeverTrueWhenAPointOfTheBoxLiesOutsideTheCone) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto unit = [&] {
        for (;;) {
            const glm::dvec3 v(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
            const double l = glm::length(v);
            if (l > 0.1 && l <= 1.0)
                return v / l;
        }
    };
    int inside = 0, outside = 0, sure_inside = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const glm::dvec3 apex(10 * u(rng) - 5, 10 * u(rng) - 5, 10 * u(rng) - 5);
        const glm::dvec3 axis = unit();
        const double half = (1.0 + 59.0 * u(rng)) * kPi / 180.0;
        // A box near the cone's surface more often than not: its centre at up to 1.3·half from
        // the axis, 0.3…20 m away, 1 cm…2 m along each side (flat and long ones too).
        const glm::dvec3 side = glm::normalize(glm::cross(axis, unit()));
        const double phi = 1.3 * half * u(rng);
        const glm::dvec3 dir = std::cos(phi) * axis + std::sin(phi) * side;
        const glm::dvec3 centre = apex + dir * (0.3 + 19.7 * u(rng));
        const glm::dvec3 half_size(0.005 + u(rng), 0.005 + u(rng), 0.005 + u(rng) * u(rng));
        Aabb box;
        box.extend(glm::vec3(centre - half_size));
        box.extend(glm::vec3(centre + half_size));
        const bool got =
            boxInsideCone(box, glm::vec3(apex), glm::vec3(axis), static_cast<float>(half));
        // Brute force: the 8 corners and points sampled inside and on the faces.
        const glm::dvec3 lo(box.min), hi(box.max);
        double worst = 0.0;
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
            worst = std::max(worst, angleToAxisRad(p, apex, axis));
        }
        for (int s = 0; s < 48; ++s) {
            glm::dvec3 t(u(rng), u(rng), u(rng));
            if (s % 2 == 0)
                t[s % 3] = (s % 4 == 0) ? 0.0 : 1.0;  // on a face
            worst = std::max(worst, angleToAxisRad(lo + t * (hi - lo), apex, axis));
        }
        const bool apex_in_box =
            glm::all(glm::greaterThanEqual(apex, lo)) && glm::all(glm::lessThanEqual(apex, hi));
        if (got) {
            ++inside;
            EXPECT_FALSE(apex_in_box) << "trial " << trial;
            EXPECT_LT(worst, half)
                << "trial " << trial << ": a point of the box is " << worst * 180 / kPi
                << " deg from the axis, the cone " << half * 180 / kPi;
        } else {
            ++outside;
        }
        // The contract's own sufficient condition, with room for float rounding: the bounding
        // sphere's angular radius plus its centre's angle fits.
        const glm::dvec3 mid = 0.5 * (lo + hi);
        const double radius = 0.5 * glm::length(hi - lo);
        const double d = glm::length(mid - apex);
        if (d > 1.01 * radius &&
            angleToAxisRad(mid, apex, axis) + std::asin(radius / d) <= half - 1e-3) {
            ++sure_inside;
            EXPECT_TRUE(got) << "trial " << trial;
        }
    }
    // Both answers occur often enough for the checks above to mean something.
    EXPECT_GT(inside, 1000);
    EXPECT_GT(outside, 1000);
    EXPECT_GT(sure_inside, 1000);
}

TEST(BoxInsideCone, IsFalseWhenTheApexIsInsideOrTheConeIsEmpty) {
    Aabb box;
    box.extend({-1, -1, -11});
    box.extend({1, 1, -9});
    const glm::vec3 axis(0, 0, -1);
    const float wide = static_cast<float>(80.0 * kPi / 180.0);
    EXPECT_TRUE(boxInsideCone(box, {0, 0, 0}, axis, wide));
    EXPECT_FALSE(boxInsideCone(box, {0, 0, 0}, axis, static_cast<float>(5.0 * kPi / 180.0)));
    // The apex inside the box: directions all round.
    EXPECT_FALSE(boxInsideCone(box, {0, 0, -10}, axis, wide));
    // Just outside the box but inside its bounding sphere: still not claimed.
    EXPECT_FALSE(boxInsideCone(box, {0, 0, -8.5f}, axis, wide));
    // No cone.
    EXPECT_FALSE(boxInsideCone(box, {0, 0, 0}, axis, 0.0f));
    EXPECT_FALSE(boxInsideCone(box, {0, 0, 0}, axis, -1.0f));
    EXPECT_FALSE(boxInsideCone(box, {0, 0, 0}, axis, std::nanf("")));
    // The box behind the apex.
    EXPECT_FALSE(boxInsideCone(box, {0, 0, 0}, {0, 0, 1}, wide));
}

// One small square (two triangles) seen from the origin at `ecc_deg` off −z, `distance_m` away.
Scene squareAt(double ecc_deg, double distance_m, float half_m) {
    Scene s;
    s.name = "test:square";
    const double e = ecc_deg * kPi / 180.0;
    const glm::vec3 c(static_cast<float>(distance_m * std::sin(e)), 0.0f,
                      static_cast<float>(-distance_m * std::cos(e)));
    test::addQuad(s, c + glm::vec3(-half_m, -half_m, 0), c + glm::vec3(half_m, -half_m, 0),
                  c + glm::vec3(half_m, half_m, 0), c + glm::vec3(-half_m, half_m, 0), -1, -1,
                  {255, 255, 255, 255});
    return s;
}

TEST(TrianglesPerRing, ASmallClusterLandsInTheRingsItsConeSpans) {
    const HmdProfile profile = test::smallProfile();
    const RenderView view = fullFrameView(profile, Pose{}, Eye::kLeft, {.ipd_m = 0.0});
    const glm::vec3 axis(0, 0, -1);
    const double ring_deg = 0.5;
    for (double ecc : {0.0, 12.0, 30.0}) {
        const Scene s = squareAt(ecc, 4.0, 0.05f);
        const DrawList list = buildDrawList(s);
        ASSERT_EQ(list.clusters.size(), 1u);
        // The cluster lies wholly inside a cone 1.5° wider than its centre's eccentricity.
        ASSERT_TRUE(boxInsideCone(list.clusters[0].bounds, {0, 0, 0}, axis,
                                  static_cast<float>((ecc + 1.5) * kPi / 180.0)));
        std::vector<double> rings(120, 0.0);
        addTrianglesPerRing(list, view, 0.0f, axis, ring_deg, rings);
        EXPECT_NEAR(std::accumulate(rings.begin(), rings.end(), 0.0), 2.0, 1e-9) << ecc;
        // The square's bounding sphere spans ±1.02° around its centre.
        const int k_lo = static_cast<int>(std::floor(std::max(0.0, ecc - 1.5) / ring_deg));
        const int k_hi = static_cast<int>(std::floor((ecc + 1.5) / ring_deg));
        for (int k = 0; k < static_cast<int>(rings.size()); ++k) {
            if (k < k_lo || k > k_hi) {
                EXPECT_EQ(rings[static_cast<size_t>(k)], 0.0) << "ecc " << ecc << " ring " << k;
            }
        }
        // Centred on the centre's eccentricity.
        double mean = 0.0;
        for (size_t k = 0; k < rings.size(); ++k)
            mean += rings[k] * (static_cast<double>(k) + 0.5) * ring_deg / 2.0;
        EXPECT_NEAR(mean, std::max(ecc, 0.5), 0.3) << ecc;
    }
    // Beyond the last ring: everything in the last one, nothing lost.
    const DrawList far = buildDrawList(squareAt(40.0, 4.0, 0.05f));
    std::vector<double> few(10, 0.0);
    addTrianglesPerRing(far, view, 0.0f, axis, 1.0, few);
    EXPECT_DOUBLE_EQ(few.back(), 2.0);
    EXPECT_DOUBLE_EQ(std::accumulate(few.begin(), few.end(), 0.0), 2.0);
    // Outside the frustum (behind the eye): counted nowhere.
    Scene behind = squareAt(180.0, 4.0, 0.05f);
    std::vector<double> none(10, 0.0);
    addTrianglesPerRing(buildDrawList(behind), view, 0.0f, axis, 1.0, none);
    EXPECT_EQ(std::accumulate(none.begin(), none.end(), 0.0), 0.0);
}

#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)

struct Room {
    Scene scene;
    DrawList list;
};

const Room& room() {
    static const Room r = [] {
        Room x;
        auto s = loadScene("builtin:room?objects=8");
        EXPECT_TRUE(s.ok()) << s.error();
        if (s.ok())
            x.scene = std::move(s).value();
        x.list = buildDrawList(x.scene);
        buildLods(x.list, x.scene);
        return x;
    }();
    return r;
}

struct Look {
    double yaw, pitch;
    Gaze gaze;
};
const Look kLooks[] = {
    {0.0, -20.0, {0.0, 0.0}}, {15.0, -30.0, {-10.0, 8.0}}, {-35.0, -15.0, {10.0, -5.0}}};

glm::vec3 gazeAxis(const HmdProfile& profile, const Pose& head, Eye eye, const Gaze& gaze) {
    const Pose ep = eyePose(head, eye, CameraOptions{}.ipd_m);
    const glm::dvec3 g = EyeGeometry(profile).gazeDirection(gaze);
    return glm::normalize(glm::normalize(ep.orientation) * glm::vec3(g));
}

TEST(TrianglesPerRing, SumsToWhatSelectDrawsDrawsAtTheSameLevelOfDetail) {
    const Room& r = room();
    ASSERT_FALSE(r.scene.indices.empty());
    ASSERT_FALSE(r.list.lods.empty());
    const HmdProfile profile = test::smallProfile();
    for (const Look& look : kLooks) {
        Pose head = poseFromSpawn(r.scene.spawns.at(0));
        head.orientation = quatFromEulerDeg({look.yaw, look.pitch, 0.0});
        for (Eye eye : {Eye::kLeft, Eye::kRight}) {
            const RenderView view = fullFrameView(profile, head, eye);
            const glm::vec3 axis = gazeAxis(profile, head, eye, look.gaze);
            for (float lod_px : {0.0f, 1.0f, 4.0f}) {
                const DrawSelection sel = selectDraws(r.list, view, lod_px);
                std::vector<double> rings(90, 0.0);
                addTrianglesPerRing(r.list, view, lod_px, axis, 1.0, rings);
                const double sum = std::accumulate(rings.begin(), rings.end(), 0.0);
                EXPECT_NEAR(sum, static_cast<double>(sel.triangles), 1e-6 * sum + 1e-6)
                    << "yaw " << look.yaw << " lod " << lod_px;
                for (double v : rings)
                    EXPECT_GE(v, 0.0);
                if (lod_px == 0.0f) {
                    ASSERT_GT(sel.triangles, 1000u) << "yaw " << look.yaw;
                }
            }
        }
    }
}

// Against the scene part's exact count (a triangle counts in the ring of its least eccentric
// point inside the frustum): the cluster count is conservative (whole clusters whose box may be
// visible) and spreads a cluster over its angular extent, so it agrees in total to within the
// clusters straddling the frustum and, ring by ring, within a cluster's angular size.
TEST(TrianglesPerRing, AgreesWithTheBruteForceBvhCountAtFullDetail) {
    const Room& r = room();
    ASSERT_FALSE(r.scene.indices.empty());
    const TriangleBvh bvh(r.scene);
    const HmdProfile profile = test::smallProfile();
    const EyeGeometry geometry(profile);
    for (const Look& look : kLooks) {
        Pose head = poseFromSpawn(r.scene.spawns.at(0));
        head.orientation = quatFromEulerDeg({look.yaw, look.pitch, 0.0});
        const Eye eye = Eye::kLeft;
        const RenderView view = fullFrameView(profile, head, eye);
        std::vector<double> rings(90, 0.0);
        addTrianglesPerRing(r.list, view, 0.0f, gazeAxis(profile, head, eye, look.gaze), 1.0,
                            rings);
        const std::vector<uint64_t> exact = bvh.trianglesPerRingBruteForce(
            fullFrameEyeView(profile, head, eye), geometry.gazeDirection(look.gaze), 1.0, 90);
        const double total_exact =
            static_cast<double>(std::accumulate(exact.begin(), exact.end(), uint64_t{0}));
        const double total = std::accumulate(rings.begin(), rings.end(), 0.0);
        ASSERT_GT(total_exact, 1000.0);
        // Never fewer (clusters are culled conservatively), at most 15% more.
        EXPECT_GE(total, total_exact) << "yaw " << look.yaw;
        EXPECT_LE(total, 1.15 * total_exact) << "yaw " << look.yaw;
        // The cumulative counts within e, where LIWC reads them, within 25% (or 2000 triangles
        // where the fovea holds few) from 10° on.
        double cum = 0.0, cum_exact = 0.0;
        for (size_t k = 0; k < rings.size(); ++k) {
            cum += rings[k];
            cum_exact += static_cast<double>(exact[k]);
            if (k + 1 >= 10 && (k + 1) % 5 == 0) {
                EXPECT_NEAR(cum, cum_exact, std::max(0.25 * cum_exact, 2000.0))
                    << "yaw " << look.yaw << " within " << k + 1 << " deg";
            }
        }
    }
}

#endif

}  // namespace
}  // namespace qvr
