// pk3 archives written with libzip in the test: layered case-insensitive lookup, levels loaded
// out of a pk3 with their textures and shader scripts, and the errors for bad archives and names.
#include "qvr/scene/pk3.h"

#include <zip.h>

#include <filesystem>
#include <fstream>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/scene/bsp_loader.h"
#include "qvr/scene/scene_loader.h"
#include "test_bsp.h"

namespace qvr {
namespace {

using ::testing::HasSubstr;

class TempDir {
public:
    TempDir() {
        m_path =
            std::filesystem::temp_directory_path() /
            ("qvr_scene_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
             "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(m_path);
        std::filesystem::create_directories(m_path);
    }
    ~TempDir() { std::filesystem::remove_all(m_path); }
    std::string file(const std::string& name) const { return (m_path / name).string(); }

private:
    std::filesystem::path m_path;
};

void writeZip(const std::string& path, const std::map<std::string, std::vector<uint8_t>>& files) {
    int err = 0;
    zip_t* z = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
    ASSERT_NE(z, nullptr) << "zip_open " << err;
    for (const auto& [name, bytes] : files) {
        // libzip copies nothing until zip_close, so the map must outlive it (it does).
        zip_source_t* src = zip_source_buffer(z, bytes.data(), bytes.size(), 0);
        ASSERT_NE(src, nullptr);
        ASSERT_GE(zip_file_add(z, name.c_str(), src, ZIP_FL_OVERWRITE), 0) << zip_strerror(z);
    }
    ASSERT_EQ(zip_close(z), 0);
}

std::vector<uint8_t> bytesOf(const std::string& s) {
    return std::vector<uint8_t>(s.begin(), s.end());
}

// 2×2 texture: red, green / blue, white (top row first).
std::vector<uint8_t> sampleTga() {
    return test::makeTga(2, 2,
                         {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255});
}

TEST(Pk3, LooksFilesUpCaseInsensitivelyWithLaterArchivesWinning) {
    TempDir dir;
    writeZip(dir.file("pak0.pk3"),
             {{"Textures/Base/A.TGA", bytesOf("old")}, {"scripts/x.shader", bytesOf("s")}});
    writeZip(dir.file("pak1.pk3"), {{"textures/base/a.tga", bytesOf("new")}});
    GameFileSystem fs;
    ASSERT_TRUE(fs.addPk3Directory(dir.file("")).ok());
    EXPECT_EQ(fs.archiveCount(), 2u);
    const auto a = fs.read("TEXTURES\\base\\a.tga");
    ASSERT_TRUE(a.has_value());
    EXPECT_EQ(std::string(a->begin(), a->end()), "new");
    EXPECT_TRUE(fs.exists("scripts/X.shader"));
    EXPECT_FALSE(fs.read("textures/base/b.tga").has_value());
    EXPECT_THAT(fs.list("scripts/", ".shader"), ::testing::ElementsAre("scripts/x.shader"));
}

// A member named with "./" and "/" mixed at its front ("/./maps/a.bsp", found by pk3_fuzz) is
// listed under a name that finds it again: normalizing a normalized path changes nothing.
TEST(Pk3, MixedLeadingDotSlashAndSlashNormalizeOnce) {
    for (const char* name : {"/./maps/a.bsp", ".//maps/a.bsp", "/.//./MAPS\\a.bsp"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(normalizeGamePath(name), "maps/a.bsp");
    }
    TempDir dir;
    writeZip(dir.file("m.pk3"), {{"/./maps/a.bsp", bytesOf("abc")}});
    GameFileSystem fs;
    ASSERT_TRUE(fs.addPk3(dir.file("m.pk3")).ok());
    const auto listed = fs.list("", "");
    ASSERT_THAT(listed, ::testing::ElementsAre("maps/a.bsp"));
    EXPECT_TRUE(fs.exists(listed[0]));
    ASSERT_TRUE(fs.read(listed[0]).has_value());
}

TEST(Pk3, CorruptArchivesAndMissingDirectoriesAreErrors) {
    auto a = Pk3Archive::fromBytes(bytesOf("PK\3\4 definitely not a zip"), "junk.pk3");
    ASSERT_FALSE(a.ok());
    EXPECT_THAT(a.error(), HasSubstr("junk.pk3"));
    // Zero bytes is a valid empty archive to libzip: no members, no crash.
    const auto empty = Pk3Archive::fromBytes({}, "empty.pk3");
    if (empty.ok()) {
        EXPECT_TRUE((*empty)->names().empty());
    }
    GameFileSystem fs;
    const Status s = fs.addPk3Directory("/nonexistent/qvr/dir");
    ASSERT_FALSE(s.ok());
    EXPECT_THAT(s.error(), HasSubstr("no such directory"));
    TempDir dir;
    std::ofstream(dir.file("bad.pk3")) << "garbage";
    auto b = Pk3Archive::open(dir.file("bad.pk3"));
    ASSERT_FALSE(b.ok());
    EXPECT_THAT(b.error(), HasSubstr("bad.pk3"));
}

// A member whose headers claim far more bytes than the archive holds (found by pk3_fuzz: a
// 600-byte zip claiming 200 MB made every read allocate the claim first) is an error naming
// what was read; the buffer grows only with the bytes that really arrive.
TEST(Pk3, AMemberClaimingMoreBytesThanItHoldsIsCorrupt) {
    TempDir dir;
    writeZip(dir.file("m.pk3"), {{"maps/a.bsp", bytesOf("abc")}});
    std::ifstream in(dir.file("m.pk3"), std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    // Uncompressed size: offset 22 of the local header ("PK\3\4"), 24 of the central one
    // ("PK\1\2"); both say 200 MB.
    const uint32_t claim = 200u << 20;
    auto patch = [&](size_t at) {
        for (int k = 0; k < 4; ++k)
            bytes[at + k] = static_cast<uint8_t>(claim >> (8 * k));
    };
    size_t patched = 0;
    for (size_t i = 0; i + 4 <= bytes.size(); ++i) {
        if (bytes[i] == 'P' && bytes[i + 1] == 'K' && bytes[i + 2] == 3 && bytes[i + 3] == 4) {
            patch(i + 22);
            ++patched;
        } else if (bytes[i] == 'P' && bytes[i + 1] == 'K' && bytes[i + 2] == 1 &&
                   bytes[i + 3] == 2) {
            patch(i + 24);
            ++patched;
        }
    }
    ASSERT_EQ(patched, 2u);
    auto a = Pk3Archive::fromBytes(bytes, "claim.pk3");
    if (!a.ok())
        return;  // refused at open: also fine
    ASSERT_EQ((*a)->names().size(), 1u);
    const auto r = (*a)->read(0);
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("corrupt"));
    EXPECT_THAT(r.error(), HasSubstr("of 209715200 bytes read"));
}

TEST(Pk3, ReadsAnArchiveHeldInMemory) {
    TempDir dir;
    writeZip(dir.file("m.pk3"), {{"maps/a.bsp", bytesOf("abc")}});
    std::ifstream in(dir.file("m.pk3"), std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    auto a = Pk3Archive::fromBytes(bytes, "mem");
    ASSERT_TRUE(a.ok()) << a.error();
    ASSERT_EQ((*a)->names().size(), 1u);
    const auto r = (*a)->read("MAPS/A.BSP");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(std::string(r->begin(), r->end()), "abc");
    EXPECT_FALSE((*a)->read("maps/b.bsp").ok());
}

TEST(Pk3, LoadsALevelWithTexturesAndShaderScriptsFromAPk3) {
    TempDir dir;
    const std::string shader =
        "// comment\ntextures/test/scripted\n{\n\tqer_editorimage textures/test/other.tga\n"
        "\t{\n\t\tmap $lightmap\n\t}\n\t{\n\t\tmap textures/test/wall.tga\n\t\tblendFunc filter\n"
        "\t}\n}\n";
    writeZip(dir.file("level.pk3"), {{"maps/tiny.bsp", test::makeSampleBsp().bytes()},
                                     {"textures/test/wall.tga", sampleTga()},
                                     {"scripts/test.shader", bytesOf(shader)}});
    SceneLoadOptions o;
    o.openarena_dir = "/nonexistent";  // only the level's own archive
    o.patch_level = 2;
    const auto scene = loadScene(dir.file("level.pk3"), o);
    ASSERT_TRUE(scene.ok()) << scene.error();
    // "wall" names the image directly; "scripted" reaches the same image through its script,
    // so the two shaders share one texture.
    ASSERT_EQ(scene->textures.size(), 1u);
    const SceneTexture& t = scene->textures[0];
    EXPECT_EQ(t.width, 2);
    EXPECT_EQ(t.height, 2);
    EXPECT_EQ(t.rgba[0], 255);  // top-left red
    EXPECT_EQ(t.rgba[1], 0);
    EXPECT_EQ(t.rgba[8 + 2], 255);  // bottom-left blue
    for (const auto& b : scene->batches)
        EXPECT_EQ(b.texture, 0);
    EXPECT_EQ(scene->spawns.size(), 2u);
}

// A texture whose header claims 8192×8192 in a few bytes (stb_image decodes what the data does
// not hold as zeros: found by bsp_fuzz as a 34-byte TGA that took 256 MB and seconds) is refused
// like an undecodable one: the level loads, the shader has no image.
TEST(Pk3, ATextureClaimingMorePixelsThanTheLimitIsRefused) {
    std::vector<uint8_t> bomb = test::makeTga(2, 2, std::vector<uint8_t>(16, 255));
    bomb[12] = 0x00;  // width 8192
    bomb[13] = 0x20;
    bomb[14] = 0x00;  // height 8192
    bomb[15] = 0x20;
    TempDir dir;
    writeZip(dir.file("level.pk3"),
             {{"maps/tiny.bsp", test::makeSampleBsp().bytes()}, {"textures/test/wall.tga", bomb}});
    SceneLoadOptions o;
    o.openarena_dir = "/nonexistent";
    o.patch_level = 2;
    const auto scene = loadScene(dir.file("level.pk3"), o);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_TRUE(scene->textures.empty());
    // The same level with a real 2×2 texture there keeps it (the limit is not what refused it).
    writeZip(dir.file("ok.pk3"), {{"maps/tiny.bsp", test::makeSampleBsp().bytes()},
                                  {"textures/test/wall.tga", sampleTga()}});
    const auto ok = loadScene(dir.file("ok.pk3"), o);
    ASSERT_TRUE(ok.ok()) << ok.error();
    EXPECT_EQ(ok->textures.size(), 1u);
}

TEST(Pk3, APk3SceneMustHoldExactlyOneLevel) {
    TempDir dir;
    const auto bsp = test::makeSampleBsp().bytes();
    writeZip(dir.file("two.pk3"), {{"maps/a.bsp", bsp}, {"maps/b.bsp", bsp}});
    const auto scene = loadScene(dir.file("two.pk3"));
    ASSERT_FALSE(scene.ok());
    EXPECT_THAT(scene.error(), HasSubstr("holds 2 levels"));
    EXPECT_THAT(scene.error(), HasSubstr("a, b"));
}

TEST(Pk3, InstalledGameNamesGiveClearErrors) {
    TempDir dir;
    writeZip(dir.file("pak0.pk3"), {{"maps/alpha.bsp", test::makeSampleBsp().bytes()},
                                    {"maps/beta.bsp", test::makeSampleBsp().bytes()}});
    SceneLoadOptions o;
    o.openarena_dir = dir.file("");
    o.load_textures = false;
    const auto ok = loadScene("openarena:alpha", o);
    ASSERT_TRUE(ok.ok()) << ok.error();
    EXPECT_EQ(ok->name, "openarena:alpha");
    const auto missing = loadScene("openarena:gamma", o);
    ASSERT_FALSE(missing.ok());
    EXPECT_THAT(missing.error(), HasSubstr("no maps/gamma.bsp"));
    EXPECT_THAT(missing.error(), HasSubstr("available: alpha, beta"));
    o.nexuiz_dir = "/nonexistent/nexuiz";
    const auto nex = loadScene("nexuiz:x", o);
    ASSERT_FALSE(nex.ok());
    EXPECT_THAT(nex.error(), HasSubstr("nexuiz-data"));
    // Nexuiz levels are the same format, found the same way in their own directory.
    o.nexuiz_dir = dir.file("");
    const auto nex_ok = loadScene("nexuiz:beta", o);
    ASSERT_TRUE(nex_ok.ok()) << nex_ok.error();
    EXPECT_EQ(nex_ok->name, "nexuiz:beta");
    const auto nofile = loadScene("/nonexistent/level.bsp", o);
    ASSERT_FALSE(nofile.ok());
    EXPECT_THAT(nofile.error(), HasSubstr("no such file"));
}

TEST(Pk3, LoadsABspFileWithLooseTexturesBesideIt) {
    TempDir dir;
    std::filesystem::create_directories(dir.file("game/maps"));
    std::filesystem::create_directories(dir.file("game/textures/test"));
    {
        const auto bsp = test::makeSampleBsp().bytes();
        std::ofstream(dir.file("game/maps/t.bsp"), std::ios::binary)
            .write(reinterpret_cast<const char*>(bsp.data()),
                   static_cast<std::streamsize>(bsp.size()));
        const auto tga = sampleTga();
        std::ofstream(dir.file("game/textures/test/wall.tga"), std::ios::binary)
            .write(reinterpret_cast<const char*>(tga.data()),
                   static_cast<std::streamsize>(tga.size()));
    }
    SceneLoadOptions o;
    o.openarena_dir = "/nonexistent";
    const auto scene = loadScene(dir.file("game/maps/t.bsp"), o);
    ASSERT_TRUE(scene.ok()) << scene.error();
    EXPECT_EQ(scene->textures.size(), 1u);  // "scripted" has no script here: vertex colour
    int untextured = 0;
    for (const auto& b : scene->batches)
        untextured += b.texture < 0 ? 1 : 0;
    EXPECT_EQ(untextured, 1);
}

}  // namespace
}  // namespace qvr
