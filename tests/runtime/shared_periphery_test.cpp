// Shared periphery: grouping by pose and gaze, the group's layer and the SSIM gate by band.
#include "qvr/runtime/shared_periphery.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "../render/render_test_util.h"
#include "qvr/compose/test_pattern.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/render/periphery_pass.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/session.h"

namespace qvr::runtime {
namespace {

HmdProfile smallProfile() {
    return runtimeProfileByName("small").value();
}

// compose's test pattern, drawn on this thread alone: its parallel_for hands TBB's tasks between
// workers inside the uninstrumented libtbb, which ThreadSanitizer (the tsan preset runs these
// tests) reports as races in TBB's own headers.
ImageRgba8 testPattern(int width, int height) {
    tbb::task_arena this_thread_only(1);
    return this_thread_only.execute([&] { return renderTestPattern(width, height); });
}

Pose yawed(double yaw_deg, float x_m = 0.0f) {
    Pose p;
    p.orientation = quatFromEulerDeg({yaw_deg, 0.0, 0.0});
    p.position_m.x = x_m;
    return p;
}

// A sharing state in `mode` with headsets 1 and 2 connected.
std::unique_ptr<SharedPeriphery> twoHeadsets(SharePeripheryMode mode) {
    SharePeripheryConfig c;
    c.mode = mode;
    auto sp = std::make_unique<SharedPeriphery>(c);
    sp->join(1);
    sp->join(2);
    return sp;
}

TEST(SharedPeriphery, GroupsPosesCloseToTheirLeader) {
    SharePeripheryConfig c;
    c.max_angle_deg = 3.0;
    c.max_position_m = 0.1;
    EXPECT_TRUE(posesClose(yawed(0.0), yawed(2.5), c));
    EXPECT_FALSE(posesClose(yawed(0.0), yawed(3.5), c));
    EXPECT_FALSE(posesClose(yawed(0.0), yawed(0.0, 0.2f), c));
    const auto groups = groupByPose({yawed(0.0), yawed(20.0), yawed(1.0), yawed(21.0, 0.05f)}, c);
    ASSERT_EQ(groups.size(), 2u);
    EXPECT_EQ(groups[0], (std::vector<size_t>{0, 2}));
    EXPECT_EQ(groups[1], (std::vector<size_t>{1, 3}));
    // A pose close to a member but not to its leader starts a group of its own.
    EXPECT_EQ(groupByPose({yawed(0.0), yawed(2.5), yawed(5.0)}, c).size(), 2u);
}

TEST(SharedPeriphery, SsimByBandSeesOnlyTheBandsThatDiffer) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    const LayerRect& outer = plan.eyes[0].outer;
    ASSERT_FALSE(outer.empty());
    const ImageRgba8 own = testPattern(outer.width_px, outer.height_px);
    const auto same =
        layerSsimByBand(profile, plan, Eye::kLeft, LayerKind::kOuter, own, own, 10.0, 0.0);
    ASSERT_GE(same.size(), 3u);
    for (const BandSsim& b : same)
        EXPECT_NEAR(b.ssim, 1.0, 1e-9) << b.lo_deg;
    EXPECT_TRUE(bandsPass(same, 0.9));
    // Shift the texels beyond 40° by one texel: those bands drop, the inner ones stay whole
    // (a band's windows near the 40° edge see both, so the test looks below 30°).
    const EyeGeometry g(profile);
    ImageRgba8 shared = own;
    for (int y = 0; y < own.height(); ++y) {
        for (int x = 1; x < own.width(); ++x) {
            const double e_deg =
                g.eccentricityDeg(plan.gaze, outer.rect.x0 + (x + 0.5) * outer.scale,
                                  outer.rect.y0 + (y + 0.5) * outer.scale);
            if (e_deg <= 40.0)
                continue;
            for (int c = 0; c < 4; ++c)
                shared.at(x, y, c) = own.at(x - 1, y, c);
        }
    }
    const auto shifted =
        layerSsimByBand(profile, plan, Eye::kLeft, LayerKind::kOuter, shared, own, 10.0, 0.0);
    ASSERT_EQ(shifted.size(), same.size());
    bool outer_dropped = false;
    for (const BandSsim& b : shifted) {
        if (b.hi_deg <= 30.0) {
            EXPECT_NEAR(b.ssim, 1.0, 1e-9) << b.lo_deg;
        }
        if (b.lo_deg >= 50.0 && b.ssim < 0.9)
            outer_dropped = true;
    }
    EXPECT_TRUE(outer_dropped);
    EXPECT_FALSE(bandsPass(shifted, 0.9));
    // Texels nearer than hide_below_deg are left out.
    const auto hidden =
        layerSsimByBand(profile, plan, Eye::kLeft, LayerKind::kOuter, shared, own, 10.0, 30.0);
    EXPECT_GE(hidden.front().lo_deg, 30.0);
}

// A layer whose colour is a smooth function of the world direction, as rendered at `head`.
ImageRgba8 directionLayer(const HmdProfile& profile, const LayerRect& l, const glm::quat& head) {
    const EyeGeometry g(profile);
    ImageRgba8 img(l.width_px, l.height_px);
    for (int j = 0; j < l.height_px; ++j) {
        for (int i = 0; i < l.width_px; ++i) {
            const glm::dvec3 d = glm::dquat(head) * g.directionAt(l.rect.x0 + (i + 0.5) * l.scale,
                                                                  l.rect.y0 + (j + 0.5) * l.scale);
            img.at(i, j, 0) = static_cast<uint8_t>(128.0 + 120.0 * d.x);
            img.at(i, j, 1) = static_cast<uint8_t>(128.0 + 120.0 * d.y);
            img.at(i, j, 2) = 128;
            img.at(i, j, 3) = 255;
        }
    }
    return img;
}

TEST(SharedPeriphery, ReprojectsTheSharedRenderToTheMembersOrientation) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    const SharedLayer s = sharedLayerPlan(profile, {plan}, Eye::kLeft, LayerKind::kOuter, {}, 3.0);
    const LayerRect& shared_rect = s.plan.eyes[0].outer;
    const LayerRect& member = plan.eyes[0].outer;
    EXPECT_LT(shared_rect.rect.x0, 0);  // widened beyond the image by the margin
    const glm::quat a = quatFromEulerDeg({0.0, 0.0, 0.0});
    const glm::quat b = quatFromEulerDeg({2.0, 1.0, 0.0});
    const ImageRgba8 shared = directionLayer(profile, shared_rect, a);
    const ImageRgba8 truth = directionLayer(profile, member, b);
    ImageRgba8 reprojected, unmoved;
    reduceSharedLayer(shared, shared_rect, member, reprojected, profile, a, b);
    reduceSharedLayer(shared, shared_rect, member, unmoved, profile, a, a);
    ASSERT_EQ(reprojected.width(), member.width_px);
    const double err = test::meanAbsDiff(reprojected, truth);
    EXPECT_LT(err, 0.6);
    EXPECT_GT(test::meanAbsDiff(unmoved, truth), 3.0 * err);
}

TEST(SharedPeriphery, RotatedRectIsWhatTheOtherOrientationSees) {
    const HmdProfile profile = smallProfile();
    const PixelRect r{100, 120, 200, 220};
    const glm::quat a = quatFromEulerDeg({0.0, 0.0, 0.0});
    EXPECT_EQ(rotatedRect(profile, r, a, a), r);
    // A member turned 2° left of the render: its rect lies ~2° left in the render's image (more
    // pixels than 2° of the mean pixel angle: a pinhole's pixels are finest at the centre),
    // about as large, at the same height.
    const PixelRect m = rotatedRect(profile, r, a, quatFromEulerDeg({2.0, 0.0, 0.0}));
    const double shift_px = (r.x0 + r.x1) / 2.0 - (m.x0 + m.x1) / 2.0;
    EXPECT_GT(shift_px, 0.9 * 2.0 / profile.pixelAngleDeg());
    EXPECT_LT(shift_px, 1.5 * 2.0 / profile.pixelAngleDeg());
    EXPECT_NEAR((m.y0 + m.y1) / 2.0, (r.y0 + r.y1) / 2.0, 2.0);
    EXPECT_NEAR(m.width(), r.width(), 0.1 * r.width());
}

ImageRgba8 flatImage(const LayerRect& r, uint8_t value) {
    ImageRgba8 img;
    img.resize(r.width_px, r.height_px);
    std::fill(img.data(), img.data() + size_t(r.width_px) * size_t(r.height_px) * 4, value);
    return img;
}

// Members that play one motion a few frames apart: each takes the kept render nearest its own
// orientation, and never one that does not cover its layer as rotated to the render's.
TEST(SharedPeriphery, TakesTheNearestKeptRenderThatCoversIt) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    auto shared_periphery = twoHeadsets(SharePeripheryMode::kOn);
    SharedPeriphery& sp = *shared_periphery;
    const Eye l = Eye::kLeft;
    const LayerKind mid = LayerKind::kMiddle;
    sp.noteRequest(1, yawed(0.0), plan);
    sp.noteRequest(2, yawed(0.0), plan);
    const SharedLayer wide = sharedLayerPlan(profile, {plan}, l, mid, {}, 3.0);
    for (int k = 0; k <= 16; ++k)  // 17 renders at 0.5° steps: the first is not kept
        sp.store(1, l, mid, yawed(0.5 * k), wide, flatImage(wide.plan.eyes[0].middle, 10 * k));
    for (double yaw : {1.1, 0.0}) {
        const auto d = sp.decide(2, l, mid, yawed(yaw), plan, profile, {});
        ASSERT_EQ(d.action, SharedPeriphery::Action::kReuse) << yaw;
        const int nearest = std::max(1, static_cast<int>(std::lround(yaw / 0.5)));
        EXPECT_EQ(d.image.at(3, 3, 0), 10 * nearest) << yaw;
    }
    // A render without a margin does not cover a member turned 2° from it.
    const SharedLayer tight = sharedLayerPlan(profile, {plan}, l, mid, {}, 0.0);
    sp.forget(1);
    sp.join(1);
    sp.noteRequest(1, yawed(0.0), plan);
    sp.store(1, l, mid, yawed(0.0), tight, flatImage(tight.plan.eyes[0].middle, 7));
    EXPECT_EQ(sp.decide(2, l, mid, yawed(2.0), plan, profile, {}).action,
              SharedPeriphery::Action::kRenderShared);
    EXPECT_EQ(sp.decide(2, l, mid, yawed(0.0), plan, profile, {}).action,
              SharedPeriphery::Action::kReuse);
}

// A headset that follows another's path a few frames behind, more than the group's reach apart,
// takes the other's own render of each pose it comes to; and while it does, the other's group
// render does not widen toward where the follower looks from now. Once the follower leaves the
// path (it finds no render of its pose), the group render covers it again.
TEST(SharedPeriphery, AFollowerTakesTheRenderOfItsPoseAndCostsNoWidening) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    const Eye l = Eye::kLeft;
    const LayerKind mid = LayerKind::kMiddle;
    auto shared_periphery = twoHeadsets(SharePeripheryMode::kOn);
    SharedPeriphery& sp = *shared_periphery;
    const LayerRect& own = plan.eyes[0].middle;
    // 1.5° a frame, three frames apart: 4.5° apart, beyond the 3° of a group.
    sp.noteRequest(2, yawed(-4.5), plan);
    for (int k = 0; k < 8; ++k) {
        sp.noteRequest(1, yawed(1.5 * k), plan);
        const auto lead = sp.decide(1, l, mid, yawed(1.5 * k), plan, profile, {});
        ASSERT_EQ(lead.action, SharedPeriphery::Action::kOwn) << k;
        ASSERT_TRUE(lead.keep) << k;
        sp.store(1, l, mid, yawed(1.5 * k), SharedLayer{plan, {}}, flatImage(own, uint8_t(k)));
        if (k < 3)
            continue;
        sp.noteRequest(2, yawed(1.5 * (k - 3)), plan);
        const auto follow = sp.decide(2, l, mid, yawed(1.5 * (k - 3)), plan, profile, {});
        ASSERT_EQ(follow.action, SharedPeriphery::Action::kReuse) << k;
        EXPECT_EQ(follow.image.at(3, 3, 0), k - 3) << k;
    }
    // A still head: the render of its very pose is taken again (a still scene: the same texels).
    const auto again = sp.decide(2, l, mid, yawed(6.0), plan, profile, {});
    ASSERT_EQ(again.action, SharedPeriphery::Action::kReuse);
    EXPECT_EQ(again.image.at(3, 3, 0), 4);
    // Now 1° apart, a group, the follower off the path: its last decision took the render of its
    // pose, so the leader's group render is its own layer; the follower then finds no render
    // of its pose and none reaching it, and the leader's next group render widens toward it.
    sp.noteRequest(1, yawed(11.0), plan);
    sp.noteRequest(2, yawed(10.0), plan);
    const auto tight = sp.decide(1, l, mid, yawed(11.0), plan, profile, {});
    ASSERT_EQ(tight.action, SharedPeriphery::Action::kRenderShared);
    EXPECT_EQ(tight.shared.plan.eyes[0].middle.rect.area(), own.rect.area());
    sp.store(1, l, mid, yawed(11.0), tight.shared, flatImage(tight.shared.plan.eyes[0].middle, 50));
    EXPECT_EQ(sp.decide(2, l, mid, yawed(10.0), plan, profile, {}).action,
              SharedPeriphery::Action::kRenderShared);
    const auto wide = sp.decide(1, l, mid, yawed(11.0), plan, profile, {});
    ASSERT_EQ(wide.action, SharedPeriphery::Action::kRenderShared);
    EXPECT_GT(wide.shared.plan.eyes[0].middle.rect.area(), own.rect.area());
}

// The group's render reaches where the others will look from, not a fixed angle every way: a
// member turned 2° to one side widens it on that side only, and a member turning at a steady rate
// is covered at its next request with no margin (its extrapolation never missed).
TEST(SharedPeriphery, GroupRenderReachesWhereTheMembersWillLookFrom) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    const Eye l = Eye::kLeft;
    const LayerKind mid = LayerKind::kMiddle;
    const PixelRect own = plan.eyes[0].middle.rect;
    const glm::quat at0 = yawed(0.0).orientation, at2 = yawed(2.0).orientation;
    const SharedLayer s =
        sharedLayerPlan(profile, {plan, plan}, l, mid, {}, 0.0, MemberViews{at0, {{}, {at2}}});
    const PixelRect u = s.plan.eyes[0].middle.rect;
    EXPECT_TRUE(u.contains(own));
    EXPECT_TRUE(u.contains(rotatedRect(profile, own, at0, at2)));
    EXPECT_TRUE((u.x0 == own.x0) != (u.x1 == own.x1)) << "widened on one side only";
    const SharedLayer every_way = sharedLayerPlan(profile, {plan}, l, mid, {}, 3.0);
    EXPECT_LT(u.area(), every_way.plan.eyes[0].middle.rect.area());

    auto sp = twoHeadsets(SharePeripheryMode::kOn);
    for (int k = 0; k < 6; ++k)  // headset 2 turns 1° a request
        sp->noteRequest(2, yawed(1.0 * k), plan);
    sp->noteRequest(1, yawed(5.0), plan);
    const auto d = sp->decide(1, l, mid, yawed(5.0), plan, profile, {});
    ASSERT_EQ(d.action, SharedPeriphery::Action::kRenderShared);
    EXPECT_LT(d.shared.plan.eyes[0].middle.rect.area(), every_way.plan.eyes[0].middle.rect.area());
    EXPECT_NEAR(sp->stats().margin_deg_sum, 0.0, 1e-3);
    sp->store(1, l, mid, yawed(5.0), d.shared, flatImage(d.shared.plan.eyes[0].middle, 9));
    // 1.5° past the extrapolated 6°: not covered, so it renders anew (a 3° margin took it).
    sp->noteRequest(2, yawed(7.5), plan);
    EXPECT_EQ(sp->decide(2, l, mid, yawed(7.5), plan, profile, {}).action,
              SharedPeriphery::Action::kRenderShared);
    EXPECT_EQ(sp->decide(2, l, mid, yawed(6.0), plan, profile, {}).action,
              SharedPeriphery::Action::kReuse);
}

// Handing the renderer its own layer out of the group's: at one orientation and scale a copy (on
// the grid) or the one-texel box, which is the bilinear tap (off the grid).
TEST(SharedPeriphery, ReducesAtOneScaleAsTheBoxFilterDoes) {
    const HmdProfile profile = smallProfile();
    const glm::quat q = yawed(0.0).orientation;
    LayerRect shared;
    shared.rect = {92, 76, 92 + 2 * 70, 76 + 2 * 50};
    shared.scale = 2.0;
    shared.width_px = 70;
    shared.height_px = 50;
    const ImageRgba8 image = testPattern(shared.width_px, shared.height_px);
    PeripheryGrid g;
    g.x0 = shared.rect.x0;
    g.y0 = shared.rect.y0;
    g.scale = shared.scale;
    g.width_px = shared.width_px;
    g.height_px = shared.height_px;
    for (const int shift_px : {0, 1, 3}) {  // 0: on the group's grid; 1, 3: half a texel off
        LayerRect member = shared;
        member.rect = {100 + shift_px, 80, 100 + shift_px + 2 * 60, 80 + 2 * 40};
        member.width_px = 60;
        member.height_px = 40;
        ImageRgba8 fast, box;
        reduceSharedLayer(image, shared, member, fast, profile, q, q);
        reduceToOuter(image, g, member, box);
        ASSERT_EQ(fast.width(), box.width());
        ASSERT_EQ(fast.height(), box.height());
        EXPECT_LT(test::meanAbsDiff(fast, box), shift_px == 0 ? 1e-9 : 0.6) << shift_px;
    }
}

TEST(SharedPeriphery, GroupLayerCoversEveryMemberAtTheFinestScale) {
    const HmdProfile profile = smallProfile();
    const LayerPlanner planner(profile);
    const LayerPlan a = planner.plan({0.0, 0.0}, 10.0);
    const LayerPlan b = planner.plan({0.0, 0.0}, 25.0);
    ASSERT_NE(a.eyes[0].outer.scale, b.eyes[0].outer.scale);
    const LayerHoles holes{.enabled = true};
    const SharedLayer s = sharedLayerPlan(profile, {a, b}, Eye::kLeft, LayerKind::kOuter, holes);
    const LayerRect& u = s.plan.eyes[0].outer;
    EXPECT_DOUBLE_EQ(u.scale, std::min(a.eyes[0].outer.scale, b.eyes[0].outer.scale));
    EXPECT_TRUE(u.rect.contains(a.eyes[0].outer.rect));
    EXPECT_TRUE(u.rect.contains(b.eyes[0].outer.rect));
    // Its hole is no larger than either member's.
    const double hole = layerHoleDeg(profile, s.plan, Eye::kLeft, LayerKind::kOuter, s.holes);
    EXPECT_LE(hole, layerHoleDeg(profile, a, Eye::kLeft, LayerKind::kOuter, holes) + 1e-9);
    EXPECT_LE(hole, layerHoleDeg(profile, b, Eye::kLeft, LayerKind::kOuter, holes) + 1e-9);
    // Different gazes: different hole discs, so none.
    const LayerPlan c = planner.plan({10.0, 0.0}, 10.0);
    EXPECT_FALSE(
        sharedLayerPlan(profile, {a, c}, Eye::kLeft, LayerKind::kOuter, holes).holes.enabled);
}

// Headsets 1 and 2 sharing on auto, the small display's plan for a centred gaze, the server's
// holes.
struct AutoPair {
    HmdProfile profile;
    LayerPlan plan;
    LayerHoles holes;
    std::unique_ptr<SharedPeriphery> sp;
};
AutoPair autoPair() {
    const HmdProfile profile = smallProfile();
    return {profile, LayerPlanner(profile).plan({0.0, 0.0}, 10.0), LayerHoles{.enabled = true},
            twoHeadsets(SharePeripheryMode::kAuto)};
}

// A render made at a headset's very pose and at its scale holds the texels its own would: it
// takes it whatever the gate measured on other renders, and the renderer keeps its own layer
// for it even when no member would take a group render.
TEST(SharedPeriphery, TakesARenderOfItsVeryPoseWhateverTheGateMeasured) {
    auto [profile, plan, holes, shared_periphery] = autoPair();
    SharedPeriphery& sp = *shared_periphery;
    using A = SharedPeriphery::Action;
    const Eye l = Eye::kLeft;
    const LayerKind outer = LayerKind::kOuter;
    sp.noteRequest(1, yawed(0.0), plan);
    sp.noteRequest(2, yawed(1.0), plan);
    auto d = sp.decide(1, l, outer, yawed(0.0), plan, profile, holes);
    ASSERT_EQ(d.action, A::kRenderShared);
    sp.store(1, l, outer, yawed(0.0), d.shared, flatImage(d.shared.plan.eyes[0].outer, 5));
    ASSERT_EQ(sp.decide(2, l, outer, yawed(1.0), plan, profile, holes).action, A::kMeasure);
    sp.measured(2, l, outer, {{60.0, 70.0, 0.5, 100}});
    d = sp.decide(1, l, outer, yawed(0.0), plan, profile, holes);
    ASSERT_EQ(d.action, A::kOwn);
    EXPECT_TRUE(d.keep);
    sp.store(1, l, outer, yawed(0.0), SharedLayer{plan, holes}, flatImage(plan.eyes[0].outer, 9));
    sp.noteRequest(2, yawed(0.0), plan);
    d = sp.decide(2, l, outer, yawed(0.0), plan, profile, holes);
    ASSERT_EQ(d.action, A::kReuse);
    EXPECT_EQ(d.image.at(3, 3, 0), 9);
}

TEST(SharedPeriphery, ReusesAnotherMembersRenderOnlyWhileTheMeasurementPasses) {
    auto [profile, plan, holes, shared_periphery] = autoPair();
    SharedPeriphery& sp = *shared_periphery;
    using A = SharedPeriphery::Action;
    sp.noteRequest(1, yawed(0.0), plan);
    EXPECT_EQ(sp.decide(1, Eye::kLeft, LayerKind::kOuter, yawed(0.0), plan, profile, holes).action,
              A::kOwn);
    sp.noteRequest(2, yawed(1.0), plan);
    auto d = sp.decide(1, Eye::kLeft, LayerKind::kOuter, yawed(0.0), plan, profile, holes);
    ASSERT_EQ(d.action, A::kRenderShared);
    const SharedLayer shared = d.shared;
    const LayerRect rect = shared.plan.eyes[0].outer;
    const ImageRgba8 layer = testPattern(rect.width_px, rect.height_px);
    sp.store(1, Eye::kLeft, LayerKind::kOuter, yawed(0.0), shared, layer);
    // Headset 2 measures before it shares; a passing measurement lets it reuse the next one.
    d = sp.decide(2, Eye::kLeft, LayerKind::kOuter, yawed(1.0), plan, profile, holes);
    ASSERT_EQ(d.action, A::kMeasure);
    EXPECT_EQ(d.image.width(), plan.eyes[0].outer.width_px);
    sp.measured(2, Eye::kLeft, LayerKind::kOuter, {{50.0, 60.0, 0.95, 100}});
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kOuter, yawed(1.0), plan, profile, holes).action,
              A::kRenderShared);  // that render was given to it already
    sp.store(1, Eye::kLeft, LayerKind::kOuter, yawed(0.0), shared, layer);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kOuter, yawed(1.0), plan, profile, holes).action,
              A::kReuse);
    // A failing band stops the reuse until the next measurement.
    sp.measured(2, Eye::kLeft, LayerKind::kOuter,
                {{50.0, 60.0, 0.95, 100}, {60.0, 70.0, 0.5, 100}});
    sp.store(1, Eye::kLeft, LayerKind::kOuter, yawed(0.0), shared, layer);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kOuter, yawed(1.0), plan, profile, holes).action,
              A::kRenderShared);  // for headset 1, whose measurement is due
    // Headset 1 passes, headset 2 failed: nobody would take 1's group render, so it renders its
    // own layer, not the larger group one.
    sp.measured(1, Eye::kLeft, LayerKind::kOuter, {{50.0, 60.0, 0.95, 100}});
    EXPECT_EQ(sp.decide(1, Eye::kLeft, LayerKind::kOuter, yawed(0.0), plan, profile, holes).action,
              A::kOwn);
    // Far apart: each its own.
    sp.noteRequest(2, yawed(30.0), plan);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kOuter, yawed(30.0), plan, profile, holes).action,
              A::kOwn);
    // A session that left is not brought back by a late request.
    sp.forget(1);
    sp.noteRequest(1, yawed(1.0), plan);
    sp.noteRequest(2, yawed(1.0), plan);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kOuter, yawed(1.0), plan, profile, holes).action,
              A::kOwn);
    EXPECT_EQ(sp.decide(1, Eye::kLeft, LayerKind::kOuter, yawed(1.0), plan, profile, holes).action,
              A::kOwn);
    const SharePeripheryStats s = sp.stats();
    EXPECT_EQ(s.measurements, 3u);
    EXPECT_EQ(s.measurements_failed, 1u);
    EXPECT_EQ(s.outer.reused, 1u);
    EXPECT_EQ(s.middle.reused + s.middle.shared + s.middle.own, 0u);
    ASSERT_EQ(s.ssim_by_band.size(), 2u);
    EXPECT_DOUBLE_EQ(s.ssim_by_band[0].ssim_mean, 0.95);
    EXPECT_DOUBLE_EQ(s.ssim_by_band[1].ssim_min, 0.5);
}

// The middle layer is centred on the gaze: shared between close poses only when the gazes are
// close too, over the union of the members' middle rects with no hole when the gazes differ.
// The middle layer is centred on the gaze: two gazes 6° apart share one render of the union of
// their layers (a little larger than either); two 45° apart render their own (the union would
// cost more than both).
TEST(SharedPeriphery, SharesTheMiddleLayerWhileOneRenderOfTheUnionCostsLess) {
    const HmdProfile profile = smallProfile();
    const LayerPlanner planner(profile);
    const LayerPlan a = planner.plan({-20.0, -10.0}, 10.0);
    const LayerPlan near = planner.plan({-14.0, -10.0}, 10.0);
    const LayerPlan far = planner.plan({20.0, 10.0}, 10.0);
    EXPECT_TRUE(middleUnionPays(a, near));
    EXPECT_FALSE(middleUnionPays(a, far));
    const LayerHoles holes{.enabled = true};
    auto shared_periphery = twoHeadsets(SharePeripheryMode::kOn);
    SharedPeriphery& sp = *shared_periphery;
    using A = SharedPeriphery::Action;
    sp.noteRequest(1, Pose{}, a);
    sp.noteRequest(2, Pose{}, far);
    EXPECT_EQ(sp.decide(1, Eye::kLeft, LayerKind::kMiddle, Pose{}, a, profile, holes).action,
              A::kOwn);
    EXPECT_EQ(sp.decide(1, Eye::kLeft, LayerKind::kOuter, Pose{}, a, profile, holes).action,
              A::kRenderShared);
    sp.noteRequest(2, Pose{}, near);
    const auto d = sp.decide(1, Eye::kLeft, LayerKind::kMiddle, Pose{}, a, profile, holes);
    ASSERT_EQ(d.action, A::kRenderShared);
    const LayerRect& u = d.shared.plan.eyes[0].middle;
    EXPECT_TRUE(u.rect.contains(a.eyes[0].middle.rect));
    EXPECT_TRUE(u.rect.contains(near.eyes[0].middle.rect));
    EXPECT_DOUBLE_EQ(d.shared.plan.s1, u.scale);
    EXPECT_FALSE(d.shared.holes.enabled);  // two gazes, two fovea discs
    sp.store(1, Eye::kLeft, LayerKind::kMiddle, Pose{}, d.shared,
             testPattern(u.width_px, u.height_px));
    const auto reused = sp.decide(2, Eye::kLeft, LayerKind::kMiddle, Pose{}, near, profile, holes);
    ASSERT_EQ(reused.action, A::kReuse);
    EXPECT_EQ(reused.image.width(), near.eyes[0].middle.width_px);
    EXPECT_EQ(reused.image.height(), near.eyes[0].middle.height_px);
    const SharePeripheryStats s = sp.stats();
    EXPECT_EQ(s.middle.shared, 1u);
    EXPECT_EQ(s.middle.reused, 1u);
    EXPECT_EQ(s.outer.shared, 1u);
}

// A render with a hole is no use to a headset whose own layer has none there.
TEST(SharedPeriphery, NeverHandsOnARenderWithALargerHole) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    auto shared_periphery = twoHeadsets(SharePeripheryMode::kOn);
    SharedPeriphery& sp = *shared_periphery;
    sp.noteRequest(1, Pose{}, plan);
    sp.noteRequest(2, Pose{}, plan);
    const LayerRect& r = plan.eyes[0].middle;
    const ImageRgba8 img = testPattern(r.width_px, r.height_px);
    ASSERT_GT(layerHoleDeg(profile, plan, Eye::kLeft, LayerKind::kMiddle, {.enabled = true}), 0.0);
    sp.store(1, Eye::kLeft, LayerKind::kMiddle, Pose{}, SharedLayer{plan, {.enabled = true}}, img);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kMiddle, Pose{}, plan, profile, {}).action,
              SharedPeriphery::Action::kRenderShared);
    sp.store(1, Eye::kLeft, LayerKind::kMiddle, Pose{}, SharedLayer{plan, {}}, img);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kMiddle, Pose{}, plan, profile, {}).action,
              SharedPeriphery::Action::kReuse);
}

TEST(SharedPeriphery, OffNeverShares) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
    SharedPeriphery sp(SharePeripheryConfig{});
    sp.join(1);
    sp.join(2);
    sp.noteRequest(1, Pose{}, plan);
    sp.noteRequest(2, Pose{}, plan);
    EXPECT_EQ(sp.decide(2, Eye::kLeft, LayerKind::kOuter, Pose{}, plan, profile, {}).action,
              SharedPeriphery::Action::kOwn);
    RenderServerStats stats;
    stats.share_periphery = sp.stats();
    const nlohmann::json j = serverPoolJson(stats)["share_periphery"];
    EXPECT_EQ(j["mode"], "off");
    for (const char* key :
         {"min_ssim", "band_deg", "outer_layers_own", "outer_layers_shared", "outer_layers_reused",
          "middle_layers_own", "middle_layers_shared", "middle_layers_reused", "measurements",
          "measurements_failed", "service_ms_per_headset_frame", "ssim_by_band"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_FALSE(parseSharePeripheryMode("sometimes").ok());
    EXPECT_EQ(*parseSharePeripheryMode("auto"), SharePeripheryMode::kAuto);
}

}  // namespace
}  // namespace qvr::runtime
