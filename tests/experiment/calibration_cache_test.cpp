#include <cstdlib>
#include <optional>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "qvr/experiment/calibration.h"

namespace qvr::experiment {
namespace {

TEST(CalibrationCache, KeyIsSixteenHexDigitsAndStable) {
    const CalibrateOptions o;
    const std::string key = calibrationCacheKey(o);
    EXPECT_TRUE(std::regex_match(key, std::regex("[0-9a-f]{16}"))) << key;
    EXPECT_EQ(calibrationCacheKey(o), key);
}

TEST(CalibrationCache, KeyChangesWithEveryMeasuredOption) {
    const CalibrateOptions base;
    const std::string key = calibrationCacheKey(base);
    auto differs = [&](auto change) {
        CalibrateOptions o = base;
        change(o);
        return calibrationCacheKey(o) != key;
    };
    EXPECT_TRUE(differs([](CalibrateOptions& o) { o.scene = "builtin:sponza"; }));
    EXPECT_TRUE(differs([](CalibrateOptions& o) { o.profile = "run"; }));
    EXPECT_TRUE(differs([](CalibrateOptions& o) { o.codec = "raw"; }));
    EXPECT_TRUE(differs([](CalibrateOptions& o) { o.lod_px = 2.0f; }));
    EXPECT_TRUE(differs([](CalibrateOptions& o) { o.core = 1; }));
    // How many samples and how much is printed do not change what is measured.
    EXPECT_FALSE(differs([](CalibrateOptions& o) { o.quick = !o.quick; }));
    EXPECT_FALSE(differs([](CalibrateOptions& o) { o.verbose = !o.verbose; }));
}

// Sets an environment variable for a scope, restoring it after.
class EnvVar {
public:
    EnvVar(const char* name, const char* value) : m_name(name) {
        if (const char* old = std::getenv(name))
            m_old = old;
        if (value)
            ::setenv(name, value, 1);
        else
            ::unsetenv(name);
    }
    ~EnvVar() {
        if (m_old)
            ::setenv(m_name, m_old->c_str(), 1);
        else
            ::unsetenv(m_name);
    }

private:
    const char* m_name;
    std::optional<std::string> m_old;
};

TEST(CalibrationCache, PathFollowsXdgThenHomeThenTmp) {
    const CalibrateOptions o;
    const std::string file = "/qvr/calibration-" + calibrationCacheKey(o) + ".toml";
    {
        EnvVar xdg("XDG_CACHE_HOME", "/x/cache");
        EnvVar home("HOME", "/h");
        EXPECT_EQ(calibrationCachePath(o), "/x/cache" + file);
    }
    {
        EnvVar xdg("XDG_CACHE_HOME", "");
        EnvVar home("HOME", "/h");
        EXPECT_EQ(calibrationCachePath(o), "/h/.cache" + file);
    }
    {
        EnvVar xdg("XDG_CACHE_HOME", nullptr);
        EnvVar home("HOME", nullptr);
        EXPECT_EQ(calibrationCachePath(o), "/tmp" + file);
    }
}

}  // namespace
}  // namespace qvr::experiment
