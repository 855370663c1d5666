// The Quake III BSP loader on a generated level and on malformed ones: every defect must come
// back as an error that names it, never a crash.
#include "qvr/scene/bsp_loader.h"

#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "test_bsp.h"

namespace qvr {
namespace {

using test::getInt;
using test::lumpDirectoryAt;
using test::makeSampleBsp;
using test::putInt;
using ::testing::HasSubstr;

SceneLoadOptions noTextures(int patch_level = 4) {
    SceneLoadOptions o;
    o.patch_level = patch_level;
    o.load_textures = false;
    return o;
}

Expected<Scene> parse(const std::vector<uint8_t>& bytes, const SceneLoadOptions& o = noTextures(),
                      BspStats* stats = nullptr) {
    return parseBsp(bytes, "test.bsp", nullptr, o, stats);
}

TEST(BspLoader, LoadsPolygonMeshAndPatchFacesOfAGeneratedLevel) {
    BspStats stats;
    const auto scene = parse(makeSampleBsp().bytes(), noTextures(4), &stats);
    ASSERT_TRUE(scene.ok()) << scene.error();
    const SceneTriangleCounts c = countSceneTriangles(*scene);
    EXPECT_EQ(c.triangles, 3u);                // quad (2) + mesh (1)
    EXPECT_EQ(c.patch_triangles, 2u * 4 * 4);  // one 3×3 sub-patch at level 4
    EXPECT_EQ(stats.faces, 5);
    EXPECT_EQ(stats.faces_drawn, 3);
    EXPECT_EQ(stats.faces_sky_or_nodraw, 1);
    EXPECT_EQ(stats.faces_bad_shader, 1);
    EXPECT_TRUE(validateScene(*scene).ok());
    ASSERT_EQ(scene->lightmaps.size(), 1u);
    EXPECT_TRUE(scene->textures.empty());
}

TEST(BspLoader, PatchTriangleCountFollowsTheTessellationLevel) {
    for (int level : {1, 3, 8, 16}) {
        const auto scene = parse(makeSampleBsp().bytes(), noTextures(level));
        ASSERT_TRUE(scene.ok()) << scene.error();
        EXPECT_EQ(countSceneTriangles(*scene).patch_triangles,
                  2u * static_cast<uint64_t>(level * level));
    }
    EXPECT_FALSE(parse(makeSampleBsp().bytes(), noTextures(0)).ok());
    EXPECT_FALSE(parse(makeSampleBsp().bytes(), noTextures(65)).ok());
    SceneLoadOptions o = noTextures();
    o.lightmap_overbright_bits = 9;
    EXPECT_FALSE(parse(makeSampleBsp().bytes(), o).ok());
    o.lightmap_overbright_bits = 0;  // unbrightened: the lump's bytes as they are
    const auto raw = parse(makeSampleBsp().bytes(), o);
    ASSERT_TRUE(raw.ok()) << raw.error();
    EXPECT_EQ(raw->lightmaps[0].rgba[2], 200);
}

TEST(BspLoader, PatchSurfacePassesThroughItsCornersAndBulgesAQuarterOfTheMiddlePoint) {
    const auto scene = parse(makeSampleBsp().bytes(), noTextures(2));
    ASSERT_TRUE(scene.ok()) << scene.error();
    float max_y = -1e9f;
    bool corner = false;
    for (const auto& b : scene->batches) {
        if (!b.is_patch)
            continue;
        for (uint32_t i = b.first_index; i < b.first_index + b.index_count; ++i) {
            const glm::vec3 p = scene->vertices[scene->indices[i]].position;
            max_y = std::max(max_y, p.y);
            corner |= glm::length(p - quakeToScene({128, 0, 0})) < 1e-5f;
        }
    }
    EXPECT_TRUE(corner);
    // The biquadratic weight of the middle control point peaks at (2·½·½)² = ¼: 8 of 32 units.
    EXPECT_NEAR(max_y, 8 * kQuakeUnitM, 1e-5f);
}

TEST(BspLoader, ConvertsUnitsAxesAndWindingToOpenGl) {
    const auto scene = parse(makeSampleBsp().bytes());
    ASSERT_TRUE(scene.ok()) << scene.error();
    // Quake (64, 64, 0) inches, z up → (1.6256, 0, −1.6256) m, y up.
    const glm::vec3 q = quakeToScene({64, 64, 0});
    EXPECT_NEAR(q.x, 1.6256f, 1e-6f);
    EXPECT_NEAR(q.y, 0.0f, 1e-6f);
    EXPECT_NEAR(q.z, -1.6256f, 1e-6f);
    EXPECT_NEAR(scene->vertices[0].normal.y, 1.0f, 1e-6f);  // Quake +z normal → +y
    // Every drawn triangle is counter-clockwise seen from the side its normals point to.
    for (size_t t = 0; t < scene->indices.size(); t += 3) {
        const SceneVertex& a = scene->vertices[scene->indices[t]];
        const SceneVertex& b = scene->vertices[scene->indices[t + 1]];
        const SceneVertex& c = scene->vertices[scene->indices[t + 2]];
        const glm::vec3 n = glm::cross(b.position - a.position, c.position - a.position);
        EXPECT_GT(glm::dot(n, a.normal + b.normal + c.normal), 0.0f) << "triangle " << t / 3;
    }
    EXPECT_NEAR(scene->bounds.min.x, 0.0f, 1e-6f);
    EXPECT_NEAR(scene->bounds.max.x, 192 * kQuakeUnitM, 1e-5f);
    EXPECT_NEAR(scene->bounds.max.y, 64 * kQuakeUnitM, 1e-5f);
}

TEST(BspLoader, ReadsSpawnPointsAtEyeHeightWithQvrYaw) {
    const auto scene = parse(makeSampleBsp().bytes());
    ASSERT_TRUE(scene.ok()) << scene.error();
    ASSERT_EQ(scene->spawns.size(), 2u);
    const glm::vec3 eye = quakeToScene({64, 128, 32 + kQuakeSpawnEyeUnits});
    EXPECT_NEAR(glm::length(scene->spawns[0].position_m - eye), 0.0f, 1e-5f);
    EXPECT_NEAR(scene->spawns[0].yaw_deg, 0.0f, 1e-4f);    // Quake 90° (north) = qvr −z
    EXPECT_NEAR(scene->spawns[1].yaw_deg, -90.0f, 1e-4f);  // Quake 0° (east) = qvr +x
}

TEST(BspLoader, BrightensLightmapsKeepingHue) {
    const auto scene = parse(makeSampleBsp().bytes());
    ASSERT_TRUE(scene.ok()) << scene.error();
    const SceneTexture& lm = scene->lightmaps[0];
    ASSERT_EQ(lm.width, 128);
    // (10, 20, 200) << 2 = (40, 80, 800), scaled by 255 / 800.
    EXPECT_EQ(lm.rgba[0], 12);
    EXPECT_EQ(lm.rgba[1], 25);
    EXPECT_EQ(lm.rgba[2], 255);
    EXPECT_EQ(lm.rgba[3], 255);
    EXPECT_EQ(lm.rgba[4], 64);  // 16 << 2
}

TEST(BspLoader, SkipsFacesOfMissingShadersAndDrawsTheRest) {
    auto b = makeSampleBsp();
    b.faces[0].shader = -3;
    BspStats stats;
    const auto scene = parse(b.bytes(), noTextures(), &stats);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_EQ(stats.faces_bad_shader, 2);
    EXPECT_EQ(countSceneTriangles(*scene).triangles, 1u);
}

// ---- malformed files ----

void expectError(const std::vector<uint8_t>& bytes, const std::string& fragment) {
    const auto scene = parse(bytes);
    ASSERT_FALSE(scene.ok()) << "expected an error containing '" << fragment << "'";
    EXPECT_THAT(scene.error(), HasSubstr(fragment));
    EXPECT_THAT(scene.error(), HasSubstr("test.bsp"));
}

TEST(BspLoaderMalformed, TruncatedHeader) {
    auto bytes = makeSampleBsp().bytes();
    bytes.resize(100);
    expectError(bytes, "truncated header");
    expectError({}, "truncated header");
}

TEST(BspLoaderMalformed, WrongMagicOrVersion) {
    auto bytes = makeSampleBsp().bytes();
    bytes[0] = 'V';
    expectError(bytes, "magic is \"VBSP\"");
    bytes = makeSampleBsp().bytes();
    putInt(bytes, 4, 47);
    expectError(bytes, "version 47");
}

TEST(BspLoaderMalformed, LumpOutsideTheFile) {
    auto bytes = makeSampleBsp().bytes();
    putInt(bytes, lumpDirectoryAt(test::kBspLumpFaces) + 4, 1 << 30);
    expectError(bytes, "outside the");
    bytes = makeSampleBsp().bytes();
    putInt(bytes, lumpDirectoryAt(test::kBspLumpVertices), static_cast<int32_t>(bytes.size()) - 8);
    expectError(bytes, "lump 10 (vertices)");
    // The last lump's end one byte past the file.
    bytes = makeSampleBsp().bytes();
    bytes.pop_back();
    expectError(bytes, "outside the");
}

TEST(BspLoaderMalformed, NegativeOffsetsLengthsAndCounts) {
    auto bytes = makeSampleBsp().bytes();
    putInt(bytes, lumpDirectoryAt(test::kBspLumpShaders) + 4, -72);
    expectError(bytes, "negative");
    bytes = makeSampleBsp().bytes();
    putInt(bytes, lumpDirectoryAt(test::kBspLumpMeshIndices), -4);
    expectError(bytes, "negative");
    auto b = makeSampleBsp();
    b.faces[1].vertex_count = -1;
    expectError(b.bytes(), "face 1: negative");
    b = makeSampleBsp();
    b.faces[0].index_count = -6;
    expectError(b.bytes(), "face 0: negative");
}

TEST(BspLoaderMalformed, LumpNotWholeRecords) {
    auto bytes = makeSampleBsp().bytes();
    const size_t at = lumpDirectoryAt(test::kBspLumpFaces) + 4;
    putInt(bytes, at, getInt(bytes, at) - 1);
    expectError(bytes, "not a multiple of its 104-byte records");
}

TEST(BspLoaderMalformed, IndexPastTheFaceVertices) {
    auto b = makeSampleBsp();
    b.mesh_indices[2] = 4;  // the quad has 4 vertices: 0…3
    expectError(b.bytes(), "face 0: index 2 = 4 is outside the face's 4 vertices");
    b = makeSampleBsp();
    b.mesh_indices[0] = -1;
    expectError(b.bytes(), "outside the face's");
    b = makeSampleBsp();
    b.faces[1].first_vertex = 15;  // 15 + 3 > 16 vertices
    expectError(b.bytes(), "face 1: vertices [15, 18) past the 16");
    b = makeSampleBsp();
    b.faces[1].first_index = 8;
    expectError(b.bytes(), "face 1: indices [8, 11) past the 9");
    b = makeSampleBsp();
    b.faces[1].index_count = 2;
    expectError(b.bytes(), "not whole triangles");
}

TEST(BspLoaderMalformed, BadPatchSizes) {
    auto b = makeSampleBsp();
    b.faces[2].patch_width = 1 << 20;
    expectError(b.bytes(), "face 2: patch size 1048576x3 is invalid");
    b = makeSampleBsp();
    b.faces[2].patch_width = 4;
    expectError(b.bytes(), "patch size 4x3");
    b = makeSampleBsp();
    b.faces[2].patch_height = -3;
    expectError(b.bytes(), "patch size 3x-3");
    b = makeSampleBsp();
    b.faces[2].patch_width = 5;  // needs 15 vertices, the face has 9
    expectError(b.bytes(), "needs 15 vertices");
}

TEST(BspLoaderMalformed, TooManyTrianglesIsRefused) {
    SceneLoadOptions o = noTextures(64);
    o.max_triangles = 100;
    const auto scene = parse(makeSampleBsp().bytes(), o);
    ASSERT_FALSE(scene.ok());
    EXPECT_THAT(scene.error(), HasSubstr("limit of 100 triangles"));
}

TEST(BspLoaderMalformed, NonFiniteVertex) {
    auto b = makeSampleBsp();
    b.vertices[5].xyz[1] = std::numeric_limits<float>::quiet_NaN();
    expectError(b.bytes(), "vertex 5: position");
    b = makeSampleBsp();
    b.vertices[2].xyz[0] = 1e30f;
    expectError(b.bytes(), "vertex 2: position");
}

TEST(BspLoaderMalformed, MalformedEntitiesOnlyLoseSpawnPoints) {
    auto b = makeSampleBsp();
    b.entities =
        "{ \"classname\" \"info_player_start\" \"origin\" \"1 2 3\" }\n{ \"classname\" \"inf";
    auto scene = parse(b.bytes());
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_EQ(scene->spawns.size(), 1u);
    b.entities = "{ \"classname\" \"info_player_start\" \"origin\" \"1 nan 3\" }";
    scene = parse(b.bytes());
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_TRUE(scene->spawns.empty());
}

TEST(BspLoaderMalformed, EveryTruncationAndRandomCorruptionFailsCleanly) {
    const auto good = makeSampleBsp().bytes();
    for (size_t n = 0; n < good.size(); ++n) {
        const std::vector<uint8_t> cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
        EXPECT_FALSE(parse(cut).ok()) << n;
    }
    std::mt19937 rng(7);
    int failures = 0;
    for (int iter = 0; iter < 3000; ++iter) {
        auto bytes = good;
        const int flips = 1 + static_cast<int>(rng() % 4);
        for (int k = 0; k < flips; ++k)
            bytes[rng() % bytes.size()] = static_cast<uint8_t>(rng());
        const auto scene = parse(bytes, noTextures(2));
        if (!scene.ok()) {
            EXPECT_FALSE(scene.error().empty());
            ++failures;
        } else {
            EXPECT_TRUE(validateScene(*scene).ok()) << validateScene(*scene).error();
        }
    }
    EXPECT_GT(failures, 0);
}

}  // namespace
}  // namespace qvr
