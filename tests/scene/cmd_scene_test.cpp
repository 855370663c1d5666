// `qvr scene info` and `qvr scene count`: JSON with the documented fields on good input, a
// message and exit status 2 on bad input. Runs the qvr binary built next to this test.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

fs::path qvrBinary() {
    std::array<char, 4096> buf{};
    const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
    if (n <= 0)
        return {};
    // build/<dir>/tests/scene_tests → build/<dir>/apps/qvr/qvr
    return fs::path(std::string(buf.data(), static_cast<size_t>(n))).parent_path().parent_path() /
           "apps" / "qvr" / "qvr";
}

struct Outcome {
    int status = -1;
    std::string out;
    std::string err;
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

Outcome run(const std::string& args) {
    const fs::path tmp = fs::temp_directory_path() / ("qvr_scene_cli_" + std::to_string(getpid()));
    fs::create_directories(tmp);
    const std::string cmd = qvrBinary().string() + " " + args + " >" + (tmp / "out").string() +
                            " 2>" + (tmp / "err").string();
    const int raw = std::system(cmd.c_str());
    Outcome o;
    o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    o.out = slurp(tmp / "out");
    o.err = slurp(tmp / "err");
    fs::remove_all(tmp);
    return o;
}

class SceneCli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(qvrBinary()))
            GTEST_SKIP() << "qvr binary not built at " << qvrBinary();
    }
};

TEST_F(SceneCli, InfoJsonOfTheBuiltinRoom) {
    const Outcome o = run("scene info 'builtin:room?objects=4' --json");
    ASSERT_EQ(o.status, 0) << o.err;
    const auto j = nlohmann::json::parse(o.out);
    EXPECT_EQ(j["scene"], "builtin:room?objects=4");
    EXPECT_GT(j["triangles"].get<uint64_t>(), 10'000u);
    EXPECT_EQ(j["patch_triangles"].get<uint64_t>(), 0u);
    EXPECT_EQ(j["textures"].get<int>(), 6);
    EXPECT_EQ(j["lightmaps"].get<int>(), 0);
    EXPECT_GE(j["batches"].get<int>(), 4);
    EXPECT_FALSE(j["spawns"].empty());
    EXPECT_EQ(j["bounds"]["min"].size(), 3u);
}

TEST_F(SceneCli, InfoJsonOfOa_dm5) {
    if (!fs::exists("/usr/share/games/openarena/baseoa/pak1-maps.pk3"))
        GTEST_SKIP() << "openarena-081-maps not installed";
    const Outcome o = run("scene info openarena:oa_dm5 --json --patch-level 4");
    ASSERT_EQ(o.status, 0) << o.err;
    const auto j = nlohmann::json::parse(o.out);
    for (const char* key : {"triangles", "patch_triangles", "textures", "bounds", "batches",
                            "spawns", "lightmaps", "faces"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_GT(j["triangles"].get<uint64_t>(), 5'000u);
    EXPECT_GT(j["patch_triangles"].get<uint64_t>(), 1'000u);
    EXPECT_GT(j["textures"].get<int>(), 10);
    EXPECT_GT(j["lightmaps"].get<int>(), 0);
}

TEST_F(SceneCli, CountAgreesWithBruteForceAndAddsUp) {
    const Outcome o =
        run("scene count 'builtin:room?objects=8' --pitch -20 --gaze 5,-5 "
            "--brute-force --json");
    ASSERT_EQ(o.status, 0) << o.err;
    const auto j = nlohmann::json::parse(o.out);
    EXPECT_TRUE(j["brute_force_agrees"].get<bool>());
    uint64_t sum = 0;
    for (const auto& n : j["triangles_per_ring"])
        sum += n.get<uint64_t>();
    EXPECT_EQ(sum, j["triangles_in_view"].get<uint64_t>());
    EXPECT_GT(j["triangles_in_fovea_cone"].get<uint64_t>(), 0u);
    EXPECT_GE(j["triangles_not_trivially_rejected"].get<uint64_t>(), sum);
}

TEST_F(SceneCli, BadInputExitsWithStatusTwoAndAMessage) {
    for (const char* args :
         {"scene info builtin:nothing", "scene info /nonexistent/level.bsp",
          "scene info 'builtin:room?objects=-3'", "scene count builtin:room --spawn 99",
          "scene count builtin:room --gaze 1", "scene info openarena:x --patch-level 0"}) {
        const Outcome o = run(args);
        EXPECT_EQ(o.status, 2) << args;
        EXPECT_FALSE(o.err.empty()) << args;
    }
}

}  // namespace
