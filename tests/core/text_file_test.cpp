#include "qvr/core/text_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace qvr {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

fs::path scratch(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / "qvr_text_file_test";
    fs::create_directories(dir);
    return dir / name;
}

TEST(TextFile, WritesTheTextAndReplacesWhatWasThere) {
    const fs::path path = scratch("a.txt");
    ASSERT_TRUE(writeTextFile(path.string(), "first, longer text\n"));
    ASSERT_TRUE(writeTextFile(path.string(), "second\n"));
    EXPECT_EQ(readAll(path), "second\n");
}

TEST(TextFile, AFolderThatIsNotThereIsAnErrorNamingThePath) {
    const std::string path = (scratch("missing") / "no" / "b.txt").string();
    const Status st = writeTextFile(path, "x");
    ASSERT_FALSE(st);
    EXPECT_EQ(st.error(), "cannot write '" + path + "'");
}

TEST(TextFile, JsonIsIndentedByTwoWithANewlineAtTheEnd) {
    const fs::path path = scratch("c.json");
    ASSERT_TRUE(writeJsonFile(path.string(), nlohmann::json{{"b", 1}, {"a", "x"}}));
    EXPECT_EQ(readAll(path), "{\n  \"a\": \"x\",\n  \"b\": 1\n}\n");
}

}  // namespace
}  // namespace qvr
