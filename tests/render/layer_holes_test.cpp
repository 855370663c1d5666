// Holes in the periphery layers (renderer.h LayerHoles, docs/RENDER.md "Holes"): the middle
// layer leaves out the clusters wholly inside the disc the compositor takes from the fovea, the
// outer layer those inside the middle layer's disc. The hole's radius, and the promise that
// makes it safe: every pixel at or beyond it is exactly the pixel of a full draw, with fewer
// triangles submitted.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/renderer.h"
#include "render_test_util.h"
#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)
#include "qvr/scene/scene_loader.h"
#endif

namespace qvr {
namespace {

TEST(LayerHoleDeg, IsTheFinerLayersRadiusLessTheBlendBandAndMargin) {
    const HmdProfile profile = test::smallProfile();
    const double pixel_deg = profile.pixelAngleDeg();
    const LayerPlanner planner(profile);
    LayerHoles holes;
    holes.enabled = true;
    for (const Gaze gaze : {Gaze{0.0, 0.0}, Gaze{12.0, -7.0}}) {
        for (double e1 : {5.0, 10.0, 20.0}) {
            const LayerPlan plan = planner.plan(gaze, e1);
            ASSERT_TRUE(plan.hasRemote());
            ASSERT_GT(plan.s2, plan.s1);
            for (Eye eye : {Eye::kLeft, Eye::kRight}) {
                EXPECT_EQ(layerHoleDeg(profile, plan, eye, LayerKind::kFovea, holes), 0.0);
                EXPECT_NEAR(layerHoleDeg(profile, plan, eye, LayerKind::kMiddle, holes),
                            std::max(0.0, plan.e1_deg - 3.0 * plan.s1 * pixel_deg), 1e-12)
                    << "e1 " << e1;
                EXPECT_NEAR(layerHoleDeg(profile, plan, eye, LayerKind::kOuter, holes),
                            std::max(0.0, plan.e2_deg - 3.0 * plan.s2 * pixel_deg), 1e-12)
                    << "e1 " << e1;
            }
            EXPECT_GT(layerHoleDeg(profile, plan, Eye::kLeft, LayerKind::kMiddle, holes), 0.0);
            // A wider blend band and margin shrink the hole by their width in coarse texels.
            LayerHoles wide = holes;
            wide.band_texels = 4.0;
            wide.margin_texels = 0.5;
            EXPECT_NEAR(layerHoleDeg(profile, plan, Eye::kLeft, LayerKind::kMiddle, wide),
                        std::max(0.0, plan.e1_deg - 4.5 * plan.s1 * pixel_deg), 1e-12);
            // Disabled: no hole anywhere.
            for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter})
                EXPECT_EQ(layerHoleDeg(profile, plan, Eye::kLeft, kind, LayerHoles{}), 0.0);
        }
    }
    // Never negative: a fovea narrower than the band leaves no hole.
    const LayerPlan tiny = planner.plan({0.0, 0.0}, 1.0);
    ASSERT_LT(tiny.e1_deg, 3.0 * tiny.s1 * pixel_deg);
    EXPECT_EQ(layerHoleDeg(profile, tiny, Eye::kLeft, LayerKind::kMiddle, holes), 0.0);
}

TEST(LayerHoleDeg, IsZeroWhenTheFinerLayerOrTheLayerItselfIsEmpty) {
    const HmdProfile profile = test::smallProfile();
    const LayerPlanner planner(profile);
    LayerHoles holes;
    holes.enabled = true;
    const LayerPlan plan = planner.plan({3.0, 2.0}, 15.0);
    // No fovea in the left eye: its middle layer has nothing to leave out; the right eye's has.
    LayerPlan no_fovea = plan;
    no_fovea.eyes[0].fovea = LayerRect{};
    EXPECT_EQ(layerHoleDeg(profile, no_fovea, Eye::kLeft, LayerKind::kMiddle, holes), 0.0);
    EXPECT_GT(layerHoleDeg(profile, no_fovea, Eye::kRight, LayerKind::kMiddle, holes), 0.0);
    // No middle layer: the outer layer draws everything.
    LayerPlan no_middle = plan;
    no_middle.eyes[1].middle = LayerRect{};
    EXPECT_EQ(layerHoleDeg(profile, no_middle, Eye::kRight, LayerKind::kOuter, holes), 0.0);
    EXPECT_GT(layerHoleDeg(profile, no_middle, Eye::kLeft, LayerKind::kOuter, holes), 0.0);
    // A fovea that covers the field: no periphery layers, no holes.
    const LayerPlan all_local = planner.plan({0.0, 0.0}, 120.0);
    ASSERT_FALSE(all_local.hasRemote());
    for (LayerKind kind : {LayerKind::kMiddle, LayerKind::kOuter})
        EXPECT_EQ(layerHoleDeg(profile, all_local, Eye::kLeft, kind, holes), 0.0);
}

#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)

const Scene& boardScene() {
    static const Scene scene = [] {
        auto s = loadScene("builtin:room?objects=8");
        EXPECT_TRUE(s.ok()) << s.error();
        return s.ok() ? std::move(s).value() : Scene{};
    }();
    return scene;
}

struct HoleCase {
    const char* name;
    double yaw_deg, pitch_deg;
    Gaze gaze;
    double e1_deg;
};
// Standing behind the board looking down at the pieces, the gaze straight ahead or off-centre.
const HoleCase kCases[] = {
    {"ahead e1=15", 0.0, -25.0, {0.0, 0.0}, 15.0},
    {"off-centre e1=25", 10.0, -20.0, {-8.0, -6.0}, 25.0},
};

struct Compared {
    int outside = 0;         // pixels at or beyond the hole's radius, all compared
    int outside_differ = 0;  // of those, different (must stay 0)
    int inside_differ = 0;   // pixels within the hole that differ (the hole did something)
};

// Compares a layer drawn with and without its hole, pixel by pixel, at each layer texel's
// centre position in the full-resolution eye image.
Compared compareOutsideHole(const HmdProfile& profile, const LayerPlan& plan, Eye eye,
                            LayerKind kind, double hole_deg, const ImageRgba8& full,
                            const ImageRgba8& holed) {
    Compared c;
    const LayerRect& l = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
    EXPECT_EQ(full.width(), l.width_px);
    EXPECT_EQ(holed.width(), l.width_px);
    EXPECT_EQ(full.height(), l.height_px);
    EXPECT_EQ(holed.height(), l.height_px);
    const EyeGeometry geometry(profile);
    for (int j = 0; j < l.height_px; ++j) {
        for (int i = 0; i < l.width_px; ++i) {
            const double px = l.rect.x0 + (i + 0.5) * l.scale;
            const double py = l.rect.y0 + (j + 0.5) * l.scale;
            bool same = true;
            for (int ch = 0; ch < 4; ++ch)
                same = same && full.at(i, j, ch) == holed.at(i, j, ch);
            if (geometry.eccentricityDeg(plan.gaze, px, py) >= hole_deg) {
                ++c.outside;
                if (!same && ++c.outside_differ <= 5)
                    ADD_FAILURE() << layerName(kind) << " texel (" << i << ", " << j
                                  << ") at eccentricity "
                                  << geometry.eccentricityDeg(plan.gaze, px, py) << " deg, hole "
                                  << hole_deg << " deg, differs";
            } else if (!same) {
                ++c.inside_differ;
            }
        }
    }
    return c;
}

// Renders the middle and outer layers of both eyes with and without holes on `renderer`;
// `pixels` says whether the renderer draws any (the null renderer only counts).
void expectHolesKeepPixelsOutside(Renderer& renderer, bool pixels) {
    const Scene& scene = boardScene();
    ASSERT_FALSE(scene.indices.empty());
    ASSERT_TRUE(renderer.upload(scene));
    const HmdProfile profile = test::smallProfile();
    const LayerPlanner planner(profile);
    LayerHoles holes;
    holes.enabled = true;
    for (const HoleCase& hc : kCases) {
        SCOPED_TRACE(hc.name);
        Pose head = poseFromSpawn(scene.spawns.at(0));
        head.orientation = quatFromEulerDeg({hc.yaw_deg, hc.pitch_deg, 0.0});
        const LayerPlan plan = planner.plan(hc.gaze, hc.e1_deg);
        ASSERT_TRUE(plan.hasRemote());
        int inside_differ = 0;
        for (Eye eye : {Eye::kLeft, Eye::kRight}) {
            // The fovea has no hole: the same draw either way.
            ImageRgba8 fovea_full, fovea_holed;
            auto ff =
                renderLayer(renderer, profile, plan, head, eye, LayerKind::kFovea, fovea_full);
            auto fh = renderLayer(renderer, profile, plan, head, eye, LayerKind::kFovea,
                                  fovea_holed, {}, holes);
            ASSERT_TRUE(ff && fh);
            EXPECT_EQ(fh->primitives_generated, ff->primitives_generated);
            EXPECT_EQ(fh->clusters_skipped, 0u);
            for (LayerKind kind : {LayerKind::kMiddle, LayerKind::kOuter}) {
                SCOPED_TRACE(layerName(kind));
                const double hole_deg = layerHoleDeg(profile, plan, eye, kind, holes);
                ASSERT_GT(hole_deg, 0.0);
                ImageRgba8 full, holed;
                auto sf = renderLayer(renderer, profile, plan, head, eye, kind, full);
                auto sh = renderLayer(renderer, profile, plan, head, eye, kind, holed, {}, holes);
                ASSERT_TRUE(sf) << sf.error();
                ASSERT_TRUE(sh) << sh.error();
                EXPECT_EQ(sf->clusters_skipped, 0u);
                EXPECT_GT(sh->clusters_skipped, 0u) << "hole " << hole_deg << " deg";
                EXPECT_LT(sh->primitives_generated, sf->primitives_generated);
                EXPECT_EQ(sh->clusters_drawn + sh->clusters_skipped, sf->clusters_drawn);
                EXPECT_EQ(sh->clusters_culled, sf->clusters_culled);
                const Compared c =
                    compareOutsideHole(profile, plan, eye, kind, hole_deg, full, holed);
                EXPECT_GT(c.outside, 100);
                EXPECT_EQ(c.outside_differ, 0);
                inside_differ += c.inside_differ;
                if (!pixels) {
                    EXPECT_EQ(c.inside_differ, 0);
                }
            }
        }
        // On real pixels the hole shows where skipped clusters were (this comparison can fail).
        if (pixels) {
            EXPECT_GT(inside_differ, 0);
        }
    }
}

TEST(LayerHoles, NullRendererSubmitsFewerTrianglesAndTheSameImage) {
    auto r = makeNullRenderer();
    expectHolesKeepPixelsOutside(*r, false);
}

TEST(LayerHoles, GlRendererDrawsEveryPixelOutsideTheHoleAsAFullDrawDoes) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    expectHolesKeepPixelsOutside(*gl, true);
}

#endif

}  // namespace
}  // namespace qvr
