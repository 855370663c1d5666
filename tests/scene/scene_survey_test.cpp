// `qvr scene info|count` as functions: a survey of the built-in room, and a view count whose
// rings add up and agree with brute force.
#include <gtest/gtest.h>

#include "qvr/scene/builtin_scene.h"
#include "qvr/scene/scene_survey.h"

namespace qvr {
namespace {

TEST(SceneSurvey, InfoOfTheBuiltinRoom) {
    auto info = surveyScene("builtin:room", SceneLoadOptions{});
    ASSERT_TRUE(info) << info.error();
    EXPECT_EQ(info->format, "builtin");
    EXPECT_GT(info->counts.triangles, 10'000u);
    EXPECT_GT(info->bvh_nodes, 0u);
    EXPECT_FALSE(info->spawns.empty());
    const nlohmann::json j = sceneInfoJson(*info);
    EXPECT_EQ(j["triangles"].get<uint64_t>(), info->counts.triangles);
    EXPECT_FALSE(j.contains("faces"));  // Quake III levels only
    EXPECT_NE(sceneInfoText(*info).find("spawn points"), std::string::npos);
    EXPECT_FALSE(surveyScene("builtin:nope", SceneLoadOptions{}));
}

TEST(SceneSurvey, CountRingsAddUpAndAgreeWithBruteForce) {
    const Scene scene = makeBuiltinRoom(4);
    SceneCountPlan plan;
    plan.rings = 12;
    plan.brute_force = true;
    const SceneCount c = countSceneView(scene, plan);
    ASSERT_EQ(c.per_ring.size(), 12u);
    uint64_t sum = 0;
    for (uint64_t n : c.per_ring)
        sum += n;
    EXPECT_EQ(sum, c.in_view);
    EXPECT_GT(c.in_view, 0u);
    EXPECT_LE(c.in_cone, c.in_view);
    EXPECT_TRUE(c.brute_force_agrees);
    EXPECT_GE(c.not_trivially_rejected, c.in_view);
    const nlohmann::json j = sceneCountJson(c);
    EXPECT_EQ(j["triangles_in_view"].get<uint64_t>(), c.in_view);
    EXPECT_TRUE(j["brute_force_agrees"].get<bool>());
    EXPECT_NE(sceneCountText(c).find("same counts"), std::string::npos);
}

}  // namespace
}  // namespace qvr
