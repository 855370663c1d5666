// A real level, when the Debian OpenArena packages are installed: oa_dm5 loads with plausible
// counts, its textures and lightmaps, and the BVH agrees with brute force from every spawn.
#include <filesystem>
#include <numeric>

#include <gtest/gtest.h>

#include "qvr/core/pose.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/scene/triangle_bvh.h"

namespace qvr {
namespace {

bool openArenaInstalled() {
    return std::filesystem::exists("/usr/share/games/openarena/baseoa/pak1-maps.pk3");
}

TEST(OpenArena, Oa_dm5LoadsWithPlausibleCounts) {
    if (!openArenaInstalled())
        GTEST_SKIP() << "openarena-081-maps not installed";
    SceneLoadOptions o;
    o.patch_level = 4;
    const auto scene = loadScene("openarena:oa_dm5", o);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_TRUE(validateScene(*scene).ok());
    const SceneTriangleCounts c = countSceneTriangles(*scene);
    // A Quake III deathmatch level: tens of thousands of brush and model triangles, and curved
    // patches.
    EXPECT_GT(c.triangles, 5'000u);
    EXPECT_LT(c.triangles, 200'000u);
    EXPECT_GT(c.patch_triangles, 1'000u);
    EXPECT_GE(scene->spawns.size(), 4u);
    EXPECT_GE(scene->lightmaps.size(), 1u);
    EXPECT_GE(scene->textures.size(), 10u);
    const glm::vec3 size = scene->bounds.max - scene->bounds.min;
    for (int k = 0; k < 3; ++k) {
        EXPECT_GT(size[k], 5.0f);  // metres
        EXPECT_LT(size[k], 200.0f);
    }
    // Most textured batches, few untextured ones.
    int textured = 0;
    for (const auto& b : scene->batches)
        textured += b.texture >= 0 ? 1 : 0;
    EXPECT_GT(textured, static_cast<int>(scene->batches.size()) * 3 / 4);
    // Doubling the patch level quadruples the patch triangles.
    o.patch_level = 8;
    o.load_textures = false;
    const auto fine = loadScene("openarena:oa_dm5", o);
    ASSERT_TRUE(fine.ok());
    EXPECT_EQ(countSceneTriangles(*fine).patch_triangles, 4 * c.patch_triangles);
    EXPECT_EQ(countSceneTriangles(*fine).triangles, c.triangles);

    const TriangleBvh bvh(*scene);
    for (const SpawnPoint& sp : scene->spawns) {
        const EyeView v = EyeView::symmetric(glm::dvec3(sp.position_m),
                                             glm::dquat(quatFromEulerDeg({sp.yaw_deg, 0.0, 0.0})),
                                             100, 110, 0.05, 500);
        const auto rings = bvh.trianglesPerRing(v, {0, 0, -1}, 5.0, 16);
        EXPECT_EQ(rings, bvh.trianglesPerRingBruteForce(v, {0, 0, -1}, 5.0, 16));
        const uint64_t in_view = std::accumulate(rings.begin(), rings.end(), uint64_t{0});
        // From a spawn point you see part of the level, not nothing and not all of it.
        EXPECT_GT(in_view, 100u);
        EXPECT_LT(in_view, bvh.triangleCount());
    }
}

TEST(OpenArena, UnknownMapListsAvailableOnes) {
    if (!openArenaInstalled())
        GTEST_SKIP() << "openarena-081-maps not installed";
    // The closest names come first.
    const auto scene = loadScene("openarena:oa_dm55");
    ASSERT_FALSE(scene.ok());
    EXPECT_NE(scene.error().find("available: oa_dm5,"), std::string::npos) << scene.error();
    EXPECT_NE(scene.error().find("oa_dm1"), std::string::npos) << scene.error();
}

}  // namespace
}  // namespace qvr
