// builtin:room: a valid, textured, consistently wound scene whose size follows objects=N.
#include "qvr/scene/builtin_scene.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "qvr/scene/scene_loader.h"

namespace qvr {
namespace {

TEST(BuiltinRoom, IsAValidSceneWithSpawnPointsInsideIt) {
    const auto scene = loadScene("builtin:room");
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_EQ(scene->name, "builtin:room");
    EXPECT_TRUE(validateScene(*scene).ok());
    EXPECT_GT(scene->triangleCount(), 100'000u);
    EXPECT_GE(scene->textures.size(), 4u);
    ASSERT_FALSE(scene->spawns.empty());
    for (const auto& s : scene->spawns) {
        EXPECT_GT(s.position_m.x, scene->bounds.min.x);
        EXPECT_LT(s.position_m.x, scene->bounds.max.x);
        EXPECT_GT(s.position_m.y, scene->bounds.min.y);
        EXPECT_LT(s.position_m.y, scene->bounds.max.y);
        EXPECT_GT(s.position_m.z, scene->bounds.min.z);
        EXPECT_LT(s.position_m.z, scene->bounds.max.z);
    }
    for (const auto& b : scene->batches) {
        EXPECT_GE(b.texture, 0);
        EXPECT_FALSE(b.is_patch);
    }
}

TEST(BuiltinRoom, TrianglesFaceTheirNormals) {
    const Scene scene = makeBuiltinRoom(16);
    size_t agree = 0, total = 0;
    for (size_t t = 0; t < scene.indices.size(); t += 3) {
        const SceneVertex& a = scene.vertices[scene.indices[t]];
        const SceneVertex& b = scene.vertices[scene.indices[t + 1]];
        const SceneVertex& c = scene.vertices[scene.indices[t + 2]];
        const glm::vec3 n = glm::cross(b.position - a.position, c.position - a.position);
        if (glm::length(n) < 1e-8f)
            continue;  // (near-)degenerate at a lathe pole: its direction is rounding noise
        ++total;
        const bool ok = glm::dot(n, a.normal + b.normal + c.normal) > 0.0f;
        agree += ok ? 1 : 0;
        if (!ok && total - agree < 5) {
            ADD_FAILURE() << "triangle " << t / 3 << " at (" << a.position.x << ", " << a.position.y
                          << ", " << a.position.z << ") n (" << a.normal.x << ", " << a.normal.y
                          << ", " << a.normal.z << ") vs (" << n.x << ", " << n.y << ", " << n.z
                          << ")";
        }
    }
    EXPECT_GT(total, 10'000u);
    EXPECT_EQ(agree, total);
}

TEST(BuiltinRoom, ObjectCountScalesTheTriangleCount) {
    const auto empty = loadScene("builtin:room?objects=0");
    const auto few = loadScene("builtin:room?objects=8");
    const auto many = loadScene("builtin:room?objects=160");
    ASSERT_TRUE(empty.ok() && few.ok() && many.ok());
    EXPECT_LT(empty->triangleCount(), few->triangleCount());
    EXPECT_LT(few->triangleCount(), many->triangleCount());
    // Each object adds thousands of triangles.
    EXPECT_GT(many->triangleCount() - few->triangleCount(), 152u * 2000u);
    EXPECT_GT(many->bounds.max.z - many->bounds.min.z, few->bounds.max.z - few->bounds.min.z);
}

TEST(BuiltinRoom, BadNamesAreErrors) {
    for (const char* bad : {"builtin:hall", "builtin:room?objects=-1", "builtin:room?objects=x",
                            "builtin:room?objects=99999", "builtin:room?size=3"}) {
        const auto s = loadScene(bad);
        ASSERT_FALSE(s.ok()) << bad;
        EXPECT_THAT(s.error(), ::testing::HasSubstr("builtin:")) << bad;
    }
}

TEST(BuiltinRoom, TexturesCarryDetail) {
    const Scene scene = makeBuiltinRoom(0);
    for (const auto& t : scene.textures) {
        // Neighbouring texels differ: the video codec must see texture, not flat colour.
        uint64_t diff = 0;
        for (size_t i = 4; i < t.rgba.size(); i += 4)
            diff += static_cast<uint64_t>(std::abs(t.rgba[i] - t.rgba[i - 4]));
        EXPECT_GT(static_cast<double>(diff) / (t.rgba.size() / 4), 1.0) << t.name;
    }
}

}  // namespace
}  // namespace qvr
