// Assimp import of small OBJ files written by the test: triangulation, generated normals,
// material colour or texture, UV orientation.
#include "qvr/scene/assimp_loader.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/scene/scene_loader.h"
#include "test_bsp.h"

namespace qvr {
namespace {

class ObjDir : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = std::filesystem::temp_directory_path() /
                ("qvr_obj_" +
                 std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        std::filesystem::create_directories(m_dir);
    }
    void TearDown() override { std::filesystem::remove_all(m_dir); }
    std::string write(const std::string& name, const std::string& text) {
        std::ofstream((m_dir / name).string(), std::ios::binary) << text;
        return (m_dir / name).string();
    }
    std::filesystem::path m_dir;
};

TEST_F(ObjDir, TriangulatesAQuadWithMaterialColourAndGeneratedNormals) {
    write("m.mtl", "newmtl red\nKd 1 0 0\n");
    const std::string obj = write("quad.obj",
                                  "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\n"
                                  "usemtl red\nf 1 2 3 4\n");
    const auto scene = loadScene(obj);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_EQ(scene->triangleCount(), 2u);
    EXPECT_EQ(countSceneTriangles(*scene).triangles, 2u);
    ASSERT_EQ(scene->batches.size(), 1u);
    EXPECT_EQ(scene->batches[0].texture, -1);
    for (const auto& v : scene->vertices) {
        EXPECT_NEAR(v.normal.y, 1.0f, 1e-5f);  // CCW seen from +y
        EXPECT_EQ(v.color.r, 255);
        EXPECT_EQ(v.color.g, 0);
    }
    EXPECT_FALSE(scene->spawns.empty());
    EXPECT_NEAR(scene->bounds.max.x, 1.0f, 1e-6f);
}

TEST_F(ObjDir, LoadsTexturesBesideTheFileWithVZeroAtTheTop) {
    const auto tga =
        test::makeTga(2, 2, {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255});
    std::ofstream((m_dir / "t.tga").string(), std::ios::binary)
        .write(reinterpret_cast<const char*>(tga.data()), static_cast<std::streamsize>(tga.size()));
    write("m.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd t.tga\n");
    const std::string obj = write("tri.obj",
                                  "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                  "vt 0 0\nvt 1 0\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3\n");
    const auto scene = loadScene(obj);
    ASSERT_TRUE(scene.ok()) << scene.error();
    ASSERT_EQ(scene->textures.size(), 1u);
    EXPECT_EQ(scene->batches[0].texture, 0);
    // OBJ's v = 1 is the image's top row, which is row 0 of SceneTexture: v becomes 0.
    for (const auto& v : scene->vertices) {
        if (v.position.y > 0.5f)
            EXPECT_NEAR(v.uv.y, 0.0f, 1e-6f);
        else
            EXPECT_NEAR(v.uv.y, 1.0f, 1e-6f);
    }
}

TEST_F(ObjDir, GarbageAndEmptyFilesAreErrors) {
    const auto garbage = loadScene(write("bad.obj", "this is not\x01\x02 an obj f 9 9 9\n"));
    EXPECT_FALSE(garbage.ok());
    const auto empty = loadScene(write("empty.obj", "# nothing\n"));
    ASSERT_FALSE(empty.ok());
    EXPECT_THAT(empty.error(), ::testing::HasSubstr("empty.obj"));
}

TEST(AssimpLoader, LoadsTexturedGltfAndGlbFromTheAssimpTestModelsWhenInstalled) {
    const std::string dir = "/usr/share/assimp/models/glTF2/";
    for (const std::string rel :
         {"BoxTextured-glTF/BoxTextured.gltf", "BoxTextured-glTF-Binary/BoxTextured.glb",
          "BoxTextured-glTF-Embedded/BoxTextured.gltf"}) {
        if (!std::filesystem::exists(dir + rel))
            GTEST_SKIP() << dir + rel << " not installed (assimp-testmodels)";
        const auto scene = loadScene(dir + rel);
        ASSERT_TRUE(scene.ok()) << scene.error();
        EXPECT_EQ(scene->triangleCount(), 12u) << rel;
        ASSERT_EQ(scene->textures.size(), 1u) << rel;  // file, GLB chunk, data URI
        EXPECT_GT(scene->textures[0].width, 16) << rel;
        EXPECT_TRUE(validateScene(*scene).ok()) << rel;
    }
}

}  // namespace
}  // namespace qvr
