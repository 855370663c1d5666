// The GL side of LIWC's "hardware intermediate data" (paper §4.1): the triangles a view
// processes, counted by a geometry-shader clip test, agree with the driver's own clipper
// triangle by triangle, and (once the scene part is built) with the CPU BVH count.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "hand_made_scene.h"
#include "render_test_util.h"

namespace qvr {
namespace {

Scene oneTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    Scene s;
    for (const glm::vec3& p : {a, b, c}) {
        SceneVertex v;
        v.position = p;
        s.vertices.push_back(v);
    }
    s.indices = {0, 1, 2};
    SceneBatch batch;
    batch.index_count = 3;
    s.batches.push_back(batch);
    return s;
}

TEST(TriangleCount, GeometryShaderCountAgreesWithTheDriversClipperPerTriangle) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    if (!gl->info().pipeline_statistics)
        GTEST_SKIP() << "the driver has no ARB_pipeline_statistics_query to compare with";
    const HmdProfile profile = test::smallProfile();
    Pose head;
    head.orientation = quatFromEulerDeg({30.0, 10.0, 0.0});
    const RenderView view = fullFrameView(profile, head, Eye::kLeft);
    // Small triangles scattered over a region that straddles every side plane and the near
    // plane, so that inside, outside and crossing cases (and triangles outside only near a
    // frustum corner) all occur.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> centre(-3.0f, 3.0f);
    std::uniform_real_distribution<float> depth(-3.0f, 0.5f);
    std::uniform_real_distribution<float> spread(-0.6f, 0.6f);
    int inside = 0, outside = 0;
    ImageRgba8 img;
    for (int i = 0; i < 150; ++i) {
        const glm::vec3 c = head.orientation * glm::vec3(centre(rng), centre(rng), depth(rng));
        const glm::vec3 a = c + glm::vec3(spread(rng), spread(rng), spread(rng));
        const glm::vec3 b = c + glm::vec3(spread(rng), spread(rng), spread(rng));
        const glm::vec3 d = c + glm::vec3(spread(rng), spread(rng), spread(rng));
        ASSERT_TRUE(gl->upload(oneTriangle(a, b, d)));
        auto count = gl->countTrianglesInFrustum(view);
        ASSERT_TRUE(count) << count.error();
        auto stats = gl->render(view, img);
        ASSERT_TRUE(stats) << stats.error();
        ASSERT_EQ(stats->clipping_input_primitives, 1u);
        // The clipper emits the clipped polygon as a fan: ≥ 1 triangle exactly when some part
        // of the input is inside.
        const uint64_t survives = stats->clipping_output_primitives > 0 ? 1 : 0;
        EXPECT_EQ(*count, survives) << "triangle " << i;
        (survives ? inside : outside)++;
    }
    EXPECT_GT(inside, 20);
    EXPECT_GT(outside, 20);
}

TEST(TriangleCount, RoomCountsTheQuadsTheViewReaches) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const Scene room = test::texturedRoom();
    ASSERT_TRUE(gl->upload(room));
    const HmdProfile profile = test::smallProfile();
    // Looking ahead every quad but the wall behind intersects the view; the wall behind lies
    // wholly at z = +2, behind the eye.
    auto ahead = gl->countTrianglesInFrustum(fullFrameView(profile, Pose{}, Eye::kLeft));
    ASSERT_TRUE(ahead) << ahead.error();
    EXPECT_EQ(*ahead, room.triangleCount() - 2);
    // A narrow layer straight at the box's front face sees the box, the back wall and the floor
    // behind it, never the side walls or the ceiling.
    LayerRect l;
    l.rect = {150, 230, 170, 250};
    l.scale = 1.0;
    l.width_px = l.height_px = 20;
    auto narrow = gl->countTrianglesInFrustum(layerView(profile, Pose{}, Eye::kLeft, l));
    ASSERT_TRUE(narrow);
    EXPECT_LT(*narrow, *ahead);
    EXPECT_GE(*narrow, 2u);
}

}  // namespace
}  // namespace qvr
