// The null renderer: the image size and clear colour of a real one, and the triangle count of
// the batches that survive frustum culling.
#include <gtest/gtest.h>

#include "hand_made_scene.h"
#include "qvr/render/renderer.h"
#include "render_test_util.h"

namespace qvr {
namespace {

TEST(NullRenderer, FillsTheViewSizedImageWithTheClearColour) {
    auto r = makeNullRenderer();
    ASSERT_TRUE(r->upload(test::texturedRoom()));
    const LayerPlan plan = LayerPlanner(test::smallProfile()).plan({0, 0}, 10.0);
    const RenderView v = layerView(test::smallProfile(), Pose{}, Eye::kLeft, plan.eyes[0].middle);
    ImageRgba8 img;
    auto stats = r->render(v, img);
    ASSERT_TRUE(stats);
    EXPECT_EQ(img.width(), plan.eyes[0].middle.width_px);
    EXPECT_EQ(img.height(), plan.eyes[0].middle.height_px);
    for (int c = 0; c < 4; ++c)
        EXPECT_EQ(img.at(img.width() / 2, img.height() - 1, c), kClearRgba[c]);
}

TEST(NullRenderer, CountsTrianglesOfTheBatchesInsideTheFrustum) {
    auto r = makeNullRenderer();
    const Scene room = test::texturedRoom();
    ASSERT_TRUE(r->upload(room));
    const HmdProfile profile = test::smallProfile();
    ImageRgba8 img;
    // Looking down −z: everything but the wall behind (z = +2) is in view.
    auto ahead = r->render(fullFrameView(profile, Pose{}, Eye::kLeft), img);
    ASSERT_TRUE(ahead);
    EXPECT_EQ(ahead->primitives_generated, room.triangleCount() - 2);
    EXPECT_EQ(ahead->clusters_culled, 1u);
    // Turned round: the far wall and the three faces of the box are behind.
    Pose back;
    back.orientation = quatFromEulerDeg({180.0, 0.0, 0.0});
    auto behind = r->render(fullFrameView(profile, back, Eye::kLeft), img);
    ASSERT_TRUE(behind);
    EXPECT_EQ(behind->primitives_generated, room.triangleCount() - 8);
    EXPECT_EQ(behind->clusters_drawn, 5u);
}

TEST(NullRenderer, EmptySceneAndEmptyViewAreNotErrors) {
    auto r = makeNullRenderer();
    ASSERT_TRUE(r->upload(Scene{}));
    RenderView v;
    ImageRgba8 img(4, 4);
    auto stats = r->render(v, img);
    ASSERT_TRUE(stats);
    EXPECT_TRUE(img.empty());
    EXPECT_EQ(stats->primitives_generated, 0u);
}

}  // namespace
}  // namespace qvr

namespace qvr {
namespace {

TEST(NullRenderer, RenderLayerGivesEachLayerItsOwnSizeAndSkipsEmptyOnes) {
    auto r = makeNullRenderer();
    ASSERT_TRUE(r->upload(test::texturedRoom()));
    const HmdProfile profile = test::smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({-5.0, 3.0}, 12.0);
    ImageRgba8 img;
    for (Eye eye : {Eye::kLeft, Eye::kRight}) {
        for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter}) {
            const LayerRect& l = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
            ASSERT_TRUE(renderLayer(*r, profile, plan, Pose{}, eye, kind, img));
            EXPECT_EQ(img.width(), l.width_px) << layerName(kind);
            EXPECT_EQ(img.height(), l.height_px) << layerName(kind);
        }
    }
    // A fovea that covers the whole field leaves no middle or outer layer to render.
    const LayerPlan all_local = LayerPlanner(profile).plan({0.0, 0.0}, 120.0);
    ASSERT_TRUE(all_local.eyes[0].middle.empty());
    auto stats = renderLayer(*r, profile, all_local, Pose{}, Eye::kLeft, LayerKind::kMiddle, img);
    ASSERT_TRUE(stats);
    EXPECT_TRUE(img.empty());
    EXPECT_EQ(stats->primitives_generated, 0u);
}

}  // namespace
}  // namespace qvr
