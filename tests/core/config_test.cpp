// Config reading (STYLE.md §6): malformed TOML, unknown keys, wrong types and out-of-range values
// each give an error that names the source and the key; readTextFile enforces its size limit.
#include "qvr/core/config.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace qvr {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

toml::table parseOk(std::string_view text) {
    auto t = parseTomlText(text, "test.toml");
    EXPECT_TRUE(t.ok()) << (t.ok() ? "" : t.error());
    return t.ok() ? *t : toml::table{};
}

// A scratch directory unique to this test binary and test.
std::filesystem::path scratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    auto dir = std::filesystem::temp_directory_path() /
               (std::string("qvr_core_test_") + info->test_suite_name() + "_" + info->name() + "_" +
                std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

void writeFile(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary);
    out << bytes;
}

TEST(ParseTomlText, ParsesTablesWhenTextIsValid) {
    auto t = parseTomlText("a = 1\n[b]\nc = \"x\"\n", "ok.toml");
    ASSERT_TRUE(t.ok());
    EXPECT_EQ(t->at_path("a").value<int64_t>(), 1);
    EXPECT_EQ(t->at_path("b.c").value<std::string>(), "x");
}

TEST(ParseTomlText, ReportsSourceAndLineWhenMalformed) {
    const char* bad_texts[] = {
        "a = \n",             // missing value
        "[display\nw = 1\n",  // unterminated table header
        "a = 1\na = 2\n",     // duplicate key
        "x = \"unterminated\n",
        "= 3\n",
        "a = 1\n\n\nb = [1, 2\n",  // unterminated array, error on a later line
    };
    for (const char* text : bad_texts) {
        auto t = parseTomlText(text, "broken.toml");
        ASSERT_FALSE(t.ok()) << text;
        EXPECT_THAT(t.error(), HasSubstr("broken.toml:")) << text;
        EXPECT_FALSE(t.error().empty());
    }
    // The line of the problem is in the message.
    auto t = parseTomlText("a = 1\nb = 2\nc = \n", "where.toml");
    ASSERT_FALSE(t.ok());
    EXPECT_THAT(t.error(), HasSubstr("where.toml:3:"));
}

TEST(ConfigReader, ReturnsValuesAndDefaultsWhenWellFormed) {
    const auto table = parseOk("name = \"hmd\"\n[display]\nwidth_px = 640\nrefresh_hz = 72.5\n");
    ConfigReader r(table, "good.toml");
    EXPECT_EQ(r.string("name", "dflt"), "hmd");
    EXPECT_EQ(r.integer("display.width_px", 1, 16, 16384), 640);
    EXPECT_DOUBLE_EQ(r.number("display.refresh_hz", 1.0, 1.0, 1000.0), 72.5);
    // Absent keys give the default and are not errors.
    EXPECT_EQ(r.integer("display.height_px", 480, 16, 16384), 480);
    EXPECT_DOUBLE_EQ(r.number("fov.vertical_deg", 99.0, 10.0, 170.0), 99.0);
    EXPECT_EQ(r.string("missing", "dflt"), "dflt");
    EXPECT_TRUE(r.has("display.width_px"));
    EXPECT_FALSE(r.has("display.height_px"));
    EXPECT_TRUE(r.finish().ok());
}

TEST(ConfigReader, AcceptsIntegerWhenNumberIsExpected) {
    const auto table = parseOk("[display]\nrefresh_hz = 90\n");
    ConfigReader r(table, "int.toml");
    EXPECT_DOUBLE_EQ(r.number("display.refresh_hz", 1.0, 1.0, 1000.0), 90.0);
    EXPECT_TRUE(r.finish().ok());
}

TEST(ConfigReader, NamesUnknownKeyWhenNothingAskedForIt) {
    const auto table = parseOk("[display]\nwidth_px = 640\nwidht_px = 480\n[extra]\nq = 1\n");
    ConfigReader r(table, "typo.toml");
    r.integer("display.width_px", 1, 16, 16384);
    const Status st = r.finish();
    ASSERT_FALSE(st.ok());
    EXPECT_THAT(st.error(), HasSubstr("typo.toml"));
    EXPECT_THAT(st.error(), HasSubstr("display.widht_px"));
    EXPECT_THAT(st.error(), HasSubstr("extra"));
    EXPECT_THAT(st.error(), Not(HasSubstr("'display.width_px'")));
}

TEST(ConfigReader, NamesKeyWhenTypeIsWrong) {
    const auto table = parseOk(
        "[display]\nwidth_px = \"wide\"\nheight_px = 3.5\nrefresh_hz = \"fast\"\nname = 4\n");
    ConfigReader r(table, "types.toml");
    EXPECT_EQ(r.integer("display.width_px", 11, 16, 16384), 11);
    EXPECT_EQ(r.integer("display.height_px", 12, 16, 16384), 12);
    EXPECT_DOUBLE_EQ(r.number("display.refresh_hz", 13.0, 1.0, 1000.0), 13.0);
    EXPECT_EQ(r.string("display.name", "dflt"), "dflt");
    const Status st = r.finish();
    ASSERT_FALSE(st.ok());
    // Every problem of the file is in one message.
    EXPECT_THAT(st.error(), HasSubstr("'display.width_px' must be an integer"));
    EXPECT_THAT(st.error(), HasSubstr("'display.height_px' must be an integer"));
    EXPECT_THAT(st.error(), HasSubstr("'display.refresh_hz' must be a number"));
    EXPECT_THAT(st.error(), HasSubstr("'display.name' must be a string"));
    EXPECT_THAT(st.error(), HasSubstr("types.toml"));
}

TEST(ConfigReader, NamesKeyAndRangeWhenOutOfRange) {
    const auto table = parseOk(
        "[display]\nwidth_px = 0\nheight_px = 99999\nrefresh_hz = -5.0\n"
        "[fov]\nhorizontal_deg = 170.5\nvertical_deg = nan\ndiagonal_deg = inf\n");
    ConfigReader r(table, "range.toml");
    EXPECT_EQ(r.integer("display.width_px", 7, 16, 16384), 7);
    EXPECT_EQ(r.integer("display.height_px", 8, 16, 16384), 8);
    EXPECT_DOUBLE_EQ(r.number("display.refresh_hz", 9.0, 1.0, 1000.0), 9.0);
    EXPECT_DOUBLE_EQ(r.number("fov.horizontal_deg", 100.0, 10.0, 170.0), 100.0);
    EXPECT_DOUBLE_EQ(r.number("fov.vertical_deg", 110.0, 10.0, 170.0), 110.0);
    // An infinite bound does not let an infinite value through.
    EXPECT_DOUBLE_EQ(r.number("fov.diagonal_deg", 1.0, 0.0, HUGE_VAL), 1.0);
    const Status st = r.finish();
    ASSERT_FALSE(st.ok());
    EXPECT_THAT(st.error(), HasSubstr("'display.width_px' = 0 is outside [16, 16384]"));
    EXPECT_THAT(st.error(), HasSubstr("'display.height_px' = 99999"));
    EXPECT_THAT(st.error(), HasSubstr("'display.refresh_hz'"));
    EXPECT_THAT(st.error(), HasSubstr("'fov.horizontal_deg'"));
    EXPECT_THAT(st.error(), HasSubstr("'fov.vertical_deg'"));
    EXPECT_THAT(st.error(), HasSubstr("'fov.diagonal_deg'"));
}

TEST(ConfigReader, AcceptsValuesOnTheBoundsWhenInclusive) {
    const auto table = parseOk("a = 16\nb = 16384\nc = 1.0\nd = 1000.0\n");
    ConfigReader r(table, "bounds.toml");
    EXPECT_EQ(r.integer("a", 0, 16, 16384), 16);
    EXPECT_EQ(r.integer("b", 0, 16, 16384), 16384);
    EXPECT_DOUBLE_EQ(r.number("c", 0.0, 1.0, 1000.0), 1.0);
    EXPECT_DOUBLE_EQ(r.number("d", 0.0, 1.0, 1000.0), 1000.0);
    EXPECT_TRUE(r.finish().ok());
}

TEST(ConfigReader, RejectsIntegerBeyondIntWhenRangeIsWide) {
    // 2^40 does not fit an int; it must be rejected, not truncated into range.
    const auto table = parseOk("a = 1099511627776\nb = -1099511627776\n");
    ConfigReader r(table, "big.toml");
    EXPECT_EQ(r.integer("a", 5, INT32_MIN, INT32_MAX), 5);
    EXPECT_EQ(r.integer("b", 6, INT32_MIN, INT32_MAX), 6);
    const Status st = r.finish();
    ASSERT_FALSE(st.ok());
    EXPECT_THAT(st.error(), HasSubstr("'a'"));
    EXPECT_THAT(st.error(), HasSubstr("'b'"));
}

TEST(ReadTextFile, ReturnsBytesWhenWithinLimit) {
    const auto dir = scratchDir();
    std::string bytes(100, 'x');
    bytes[3] = '\0';
    bytes[50] = '\n';
    writeFile(dir / "exact.txt", bytes);
    auto text = readTextFile((dir / "exact.txt").string(), 100);
    ASSERT_TRUE(text.ok()) << text.error();
    EXPECT_EQ(*text, bytes);
    writeFile(dir / "empty.txt", "");
    auto empty = readTextFile((dir / "empty.txt").string(), 0);
    ASSERT_TRUE(empty.ok());
    EXPECT_TRUE(empty->empty());
    std::filesystem::remove_all(dir);
}

TEST(ReadTextFile, FailsWhenFileExceedsLimit) {
    const auto dir = scratchDir();
    writeFile(dir / "big.txt", std::string(101, 'y'));
    auto text = readTextFile((dir / "big.txt").string(), 100);
    ASSERT_FALSE(text.ok());
    EXPECT_THAT(text.error(), HasSubstr("big.txt"));
    EXPECT_THAT(text.error(), HasSubstr("100"));
    // Larger than one read buffer, and than the default limit of 1 MiB.
    writeFile(dir / "huge.txt", std::string((size_t{1} << 20) + 1, 'z'));
    EXPECT_FALSE(readTextFile((dir / "huge.txt").string()).ok());
    writeFile(dir / "mib.txt", std::string(size_t{1} << 20, 'z'));
    EXPECT_TRUE(readTextFile((dir / "mib.txt").string()).ok());
    std::filesystem::remove_all(dir);
}

TEST(ReadTextFile, NamesPathWhenFileIsMissing) {
    auto text = readTextFile("/nonexistent/qvr/none.toml");
    ASSERT_FALSE(text.ok());
    EXPECT_THAT(text.error(), HasSubstr("/nonexistent/qvr/none.toml"));
}

TEST(LoadTomlFile, FailsWithPathWhenMissingOrMalformed) {
    auto missing = loadTomlFile("/nonexistent/qvr/none.toml");
    ASSERT_FALSE(missing.ok());
    EXPECT_THAT(missing.error(), HasSubstr("/nonexistent/qvr/none.toml"));
    const auto dir = scratchDir();
    writeFile(dir / "bad.toml", "[display\n");
    auto bad = loadTomlFile((dir / "bad.toml").string());
    ASSERT_FALSE(bad.ok());
    EXPECT_THAT(bad.error(), HasSubstr("bad.toml:1:"));
    writeFile(dir / "good.toml", "[display]\nwidth_px = 3\n");
    auto good = loadTomlFile((dir / "good.toml").string());
    ASSERT_TRUE(good.ok()) << good.error();
    EXPECT_EQ(good->at_path("display.width_px").value<int64_t>(), 3);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace qvr
