// Eye cameras and layer sub-frusta against the pinhole of foveation/eye_geometry.h: a world
// point seen along a pixel's direction must project to that pixel in the full frame and to the
// matching texel of any layer.
#include <gtest/gtest.h>

#include <random>

#include <glm/geometric.hpp>

#include "qvr/foveation/eye_geometry.h"
#include "qvr/render/camera.h"
#include "render_test_util.h"

namespace qvr {
namespace {

// Full-resolution pixel coordinates of a world point under a view (row 0 at the top).
glm::dvec2 projectToPixel(const RenderView& v, const glm::vec3& world, double x0, double y0,
                          double scale) {
    const glm::vec4 clip = v.viewProjection() * glm::vec4(world, 1.0f);
    const double nx = clip.x / clip.w;
    const double ny = clip.y / clip.w;
    const double tx = 0.5 * (nx + 1.0) * v.width_px;
    const double ty = 0.5 * (1.0 - ny) * v.height_px;
    return {x0 + tx * scale, y0 + ty * scale};
}

TEST(Camera, FullFrameProjectsPixelDirectionsBackToTheirPixels) {
    const HmdProfile profile = test::smallProfile();
    const EyeGeometry geometry(profile);
    Pose head;
    head.orientation = quatFromEulerDeg({35.0, -10.0, 4.0});
    head.position_m = {1.0f, 1.7f, -3.0f};
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(0.0, profile.width_px);
    std::uniform_real_distribution<double> uy(0.0, profile.height_px);
    for (Eye eye : {Eye::kLeft, Eye::kRight}) {
        const Pose ep = eyePose(head, eye, 0.064);
        const RenderView v = fullFrameView(profile, head, eye);
        for (int i = 0; i < 50; ++i) {
            const double px = ux(rng), py = uy(rng);
            const glm::dvec3 d = geometry.directionAt(px, py);
            const glm::vec3 world = ep.position_m + ep.orientation * glm::vec3(d * 5.0);
            const glm::dvec2 p = projectToPixel(v, world, 0, 0, 1);
            EXPECT_NEAR(p.x, px, 2e-3);
            EXPECT_NEAR(p.y, py, 2e-3);
        }
    }
}

TEST(Camera, LayerTexelsCoverTheirRectAtTheLayerScale) {
    const HmdProfile profile = test::smallProfile();
    const EyeGeometry geometry(profile);
    const LayerPlan plan = LayerPlanner(profile).plan({8.0, -5.0}, 12.0);
    ASSERT_GT(plan.s1, 1.2);
    ASSERT_GT(plan.s2, plan.s1);
    const Pose head;
    const Pose ep = eyePose(head, Eye::kRight, 0.064);
    for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter}) {
        const LayerRect& l = layerOf(plan.eyes[1], kind);
        ASSERT_FALSE(l.empty()) << layerName(kind);
        const RenderView v = layerView(profile, head, Eye::kRight, l);
        EXPECT_EQ(v.width_px, l.width_px);
        EXPECT_EQ(v.height_px, l.height_px);
        // Corners and centre of the rect, and a point a third of the way in.
        const double pts[][2] = {{double(l.rect.x0) + 0.25, double(l.rect.y0) + 0.25},
                                 {double(l.rect.x1) - 0.25, double(l.rect.y1) - 0.25},
                                 {0.5 * (l.rect.x0 + l.rect.x1), 0.5 * (l.rect.y0 + l.rect.y1)},
                                 {l.rect.x0 + l.rect.width() / 3.0, l.rect.y1 - 1.0}};
        for (const auto& p : pts) {
            const glm::dvec3 d = geometry.directionAt(p[0], p[1]);
            const glm::vec3 world = ep.position_m + ep.orientation * glm::vec3(d * 3.0);
            const glm::dvec2 q = projectToPixel(v, world, l.rect.x0, l.rect.y0, l.scale);
            EXPECT_NEAR(q.x, p[0], 2e-3 * l.scale) << layerName(kind);
            EXPECT_NEAR(q.y, p[1], 2e-3 * l.scale) << layerName(kind);
        }
    }
}

TEST(Camera, EyesSitHalfAnIpdEitherSideAlongTheHeadsXAxis) {
    Pose head;
    head.orientation = quatFromEulerDeg({90.0, 0.0, 0.0});  // facing −x: the head's x is −z
    head.position_m = {2.0f, 1.0f, 0.0f};
    const Pose l = eyePose(head, Eye::kLeft, 0.064);
    const Pose r = eyePose(head, Eye::kRight, 0.064);
    EXPECT_NEAR(glm::distance(l.position_m, r.position_m), 0.064f, 1e-6f);
    EXPECT_NEAR(l.position_m.z, 0.032f, 1e-6f);
    EXPECT_NEAR(r.position_m.z, -0.032f, 1e-6f);
    EXPECT_NEAR(l.position_m.x, 2.0f, 1e-6f);
}

TEST(Camera, FrustumCullsBoxesBehindAndBesideTheEyeOnly) {
    const HmdProfile profile = test::smallProfile();
    const RenderView v = fullFrameView(profile, Pose{}, Eye::kLeft);
    const FrustumPlanes planes = frustumPlanes(v.viewProjection());
    auto box = [](glm::vec3 lo, glm::vec3 hi) {
        Aabb b;
        b.extend(lo);
        b.extend(hi);
        return b;
    };
    EXPECT_TRUE(boxMayBeVisible(planes, box({-0.1f, -0.1f, -2.1f}, {0.1f, 0.1f, -1.9f})));
    EXPECT_FALSE(boxMayBeVisible(planes, box({-0.1f, -0.1f, 1.9f}, {0.1f, 0.1f, 2.1f})));
    // 100° horizontal field: at 1 m ahead the edge is at x ≈ ±1.19 m.
    EXPECT_FALSE(boxMayBeVisible(planes, box({1.4f, -0.1f, -1.1f}, {1.6f, 0.1f, -0.9f})));
    EXPECT_TRUE(boxMayBeVisible(planes, box({1.0f, -0.1f, -1.1f}, {1.2f, 0.1f, -0.9f})));
    EXPECT_FALSE(boxMayBeVisible(planes, box({-0.1f, -0.1f, -500.0f}, {0.1f, 0.1f, -450.0f})));
    EXPECT_TRUE(boxMayBeVisible(planes, Aabb{}));  // unknown bounds are drawn
}

}  // namespace
}  // namespace qvr
