// A level's item entities drawn from their MD3 models (SceneLoadOptions::load_items): placed at
// the entity's origin, weapons 1.5×, marked interactive; a missing or malformed model leaves
// the item out and the level loads. The built-in room marks its chess pieces interactive.
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "qvr/scene/bsp_loader.h"
#include "qvr/scene/pk3.h"
#include "qvr/scene/scene_loader.h"
#include "test_bsp.h"

namespace qvr {
namespace {

namespace fs = std::filesystem;

void put32(std::vector<uint8_t>& b, size_t at, int32_t v) {
    std::memcpy(b.data() + at, &v, 4);
}
void put16(std::vector<uint8_t>& b, size_t at, int16_t v) {
    std::memcpy(b.data() + at, &v, 2);
}
void putF(std::vector<uint8_t>& b, size_t at, float v) {
    std::memcpy(b.data() + at, &v, 4);
}

// An MD3 of one surface, one triangle: (0,0,0), (64,0,0), (0,0,32) in Quake units.
std::vector<uint8_t> makeMd3() {
    constexpr size_t kSurf = 108, kShaders = 108, kTris = kShaders + 68, kSt = kTris + 12,
                     kXyz = kSt + 24, kEnd = kXyz + 24;
    std::vector<uint8_t> b(kSurf + kEnd, 0);
    std::memcpy(b.data(), "IDP3", 4);
    put32(b, 4, 15);
    put32(b, 76, 1);  // frames
    put32(b, 84, 1);  // surfaces
    put32(b, 100, static_cast<int32_t>(kSurf));
    put32(b, 104, static_cast<int32_t>(b.size()));
    const size_t s = kSurf;
    std::memcpy(b.data() + s, "IDP3", 4);
    put32(b, s + 72, 1);  // frames
    put32(b, s + 76, 1);  // shaders
    put32(b, s + 80, 3);  // vertices
    put32(b, s + 84, 1);  // triangles
    put32(b, s + 88, static_cast<int32_t>(kTris));
    put32(b, s + 92, static_cast<int32_t>(kShaders));
    put32(b, s + 96, static_cast<int32_t>(kSt));
    put32(b, s + 100, static_cast<int32_t>(kXyz));
    put32(b, s + 104, static_cast<int32_t>(kEnd));
    std::memcpy(b.data() + s + kShaders, "models/test/skin.tga", 20);
    for (int k = 0; k < 3; ++k)
        put32(b, s + kTris + 4 * static_cast<size_t>(k), k);
    putF(b, s + kSt + 8, 1.0f);
    const int16_t xyz[3][3] = {{0, 0, 0}, {64 * 64, 0, 0}, {0, 0, 32 * 64}};
    for (size_t v = 0; v < 3; ++v)
        for (size_t c = 0; c < 3; ++c)
            put16(b, s + kXyz + 8 * v + 2 * c, xyz[v][c]);
    return b;
}

class ItemFiles : public ::testing::Test {
protected:
    ItemFiles() : m_dir(fs::temp_directory_path() / ("qvr_items_" + std::to_string(::getpid()))) {
        write("models/weapons2/shotgun/shotgun.md3", makeMd3());
        std::vector<uint8_t> bad = makeMd3();
        bad.resize(150);  // the surface runs past the file
        write("models/powerups/armor/shard.md3", bad);
        m_files.addLooseDirectory(m_dir.string());
    }
    ~ItemFiles() override { fs::remove_all(m_dir); }
    void write(const std::string& rel, const std::vector<uint8_t>& bytes) {
        const fs::path p = m_dir / rel;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary)
            .write(reinterpret_cast<const char*>(bytes.data()),
                   static_cast<std::streamsize>(bytes.size()));
    }
    static std::vector<uint8_t> level() {
        test::TestBsp b = test::makeSampleBsp();
        b.entities +=
            "{\n\"classname\" \"weapon_shotgun\"\n\"origin\" \"100 200 16\"\n}\n"
            "{\n\"classname\" \"item_armor_shard\"\n\"origin\" \"0 0 16\"\n}\n"
            "{\n\"classname\" \"weapon_railgun\"\n\"origin\" \"0 0 16\"\n}\n";
        return b.bytes();
    }
    fs::path m_dir;
    GameFileSystem m_files;
};

TEST_F(ItemFiles, PlacesEachItemsModelAtItsOriginAsAnInteractiveBatch) {
    SceneLoadOptions o;
    o.load_textures = false;
    o.load_items = true;
    BspStats stats;
    const auto scene = parseBsp(level(), "items.bsp", &m_files, o, &stats);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_TRUE(validateScene(*scene).ok());
    // The shotgun is placed; the shard's model is malformed and the railgun's is absent.
    EXPECT_EQ(stats.items_placed, 1);
    EXPECT_EQ(stats.items_without_model, 2);
    int interactive = 0;
    for (const SceneBatch& b : scene->batches) {
        if (!b.interactive)
            continue;
        ++interactive;
        ASSERT_EQ(b.index_count, 3u);
        // Weapons are drawn 1.5×: the 64-unit edge spans 96 units from the origin.
        const glm::vec3 origin = quakeToScene({100, 200, 16});
        EXPECT_NEAR(glm::distance(b.bounds.min, quakeToScene({100, 200, 16})), 0.0f, 1e-4f);
        EXPECT_NEAR(b.bounds.max.x - origin.x, 96 * kQuakeUnitM, 1e-4f);
        EXPECT_NEAR(b.bounds.max.y - origin.y, 48 * kQuakeUnitM, 1e-4f);
    }
    EXPECT_EQ(interactive, 1);
    // Without load_items the level is as before: no interactive batch, no item counted.
    o.load_items = false;
    BspStats plain;
    const auto without = parseBsp(level(), "items.bsp", &m_files, o, &plain);
    ASSERT_TRUE(without.ok()) << without.error();
    EXPECT_EQ(without->batches.size() + 1, scene->batches.size());
    EXPECT_EQ(plain.items_placed, 0);
    for (const SceneBatch& b : without->batches)
        EXPECT_FALSE(b.interactive);
}

TEST(QuakeItems, Oa_dm5PlacesItsItems) {
    if (!fs::exists("/usr/share/games/openarena/baseoa/pak1-maps.pk3"))
        GTEST_SKIP() << "openarena-081-maps not installed";
    SceneLoadOptions o;
    o.patch_level = 4;
    o.load_items = true;
    SceneLoadReport report;
    const auto scene = loadScene("openarena:oa_dm5", o, &report);
    ASSERT_TRUE(scene.ok()) << scene.error();
    // oa_dm5 places 29 items (health, ammunition, five weapons, quad, mega health, armour).
    EXPECT_EQ(report.bsp.items_placed + report.bsp.items_without_model, 29);
    EXPECT_GE(report.bsp.items_placed, 25);
    int interactive = 0;
    for (const SceneBatch& b : scene->batches)
        interactive += b.interactive ? 1 : 0;
    EXPECT_GE(interactive, report.bsp.items_placed);
}

TEST(QuakeItems, TheBuiltinRoomsChessPiecesAreItsInteractiveObjects) {
    const auto room = loadScene("builtin:room");
    ASSERT_TRUE(room.ok()) << room.error();
    int interactive = 0;
    for (const SceneBatch& b : room->batches) {
        if (!b.interactive)
            continue;
        ++interactive;
        EXPECT_GT(b.bounds.max.y, 0.3f);  // pieces stand on the board
    }
    EXPECT_EQ(interactive, 2);  // the light and the dark pieces
    const auto empty = loadScene("builtin:room?objects=0");
    ASSERT_TRUE(empty.ok());
    for (const SceneBatch& b : empty->batches)
        EXPECT_FALSE(b.interactive);
}

}  // namespace
}  // namespace qvr
