// HMD profiles (paper §3.1, Eq. 1): TOML parsing of every section, clear errors for bad files,
// the built-in profiles, and the closed forms of ω* and the acuity scale.
#include "qvr/foveation/hmd_profile.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace qvr {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

constexpr const char* kFullProfile = R"(name = "test-hmd"

[display]
width_px = 1440
height_px = 1600
refresh_hz = 120.0

[fov]
horizontal_deg = 95.5
vertical_deg = 104

[lens]
k1 = 0.31
k2 = -0.05
chroma_red_scale = 0.995
chroma_blue_scale = 1.012

[acuity]
omega0_deg = 0.025
slope = 0.031
)";

TEST(ParseHmdProfile, ReadsEverySectionWhenFileIsComplete) {
    auto p = parseHmdProfile(kFullProfile, "full.toml");
    ASSERT_TRUE(p.ok()) << p.error();
    EXPECT_EQ(p->name, "test-hmd");
    EXPECT_EQ(p->width_px, 1440);
    EXPECT_EQ(p->height_px, 1600);
    EXPECT_DOUBLE_EQ(p->refresh_hz, 120.0);
    EXPECT_DOUBLE_EQ(p->fov_h_deg, 95.5);
    EXPECT_DOUBLE_EQ(p->fov_v_deg, 104.0);
    EXPECT_DOUBLE_EQ(p->lens.k1, 0.31);
    EXPECT_DOUBLE_EQ(p->lens.k2, -0.05);
    EXPECT_DOUBLE_EQ(p->lens.chroma_red_scale, 0.995);
    EXPECT_DOUBLE_EQ(p->lens.chroma_blue_scale, 1.012);
    EXPECT_DOUBLE_EQ(p->acuity.omega0_deg, 0.025);
    EXPECT_DOUBLE_EQ(p->acuity.slope, 0.031);
    EXPECT_NEAR(p->frameBudgetMs(), 1000.0 / 120.0, 1e-12);
}

TEST(ParseHmdProfile, KeepsDefaultsWhenKeysAreAbsent) {
    auto p = parseHmdProfile("[display]\nrefresh_hz = 72\n", "partial.toml");
    ASSERT_TRUE(p.ok()) << p.error();
    const HmdProfile d = defaultHmdProfile();
    EXPECT_DOUBLE_EQ(p->refresh_hz, 72.0);
    EXPECT_EQ(p->width_px, d.width_px);
    EXPECT_EQ(p->height_px, d.height_px);
    EXPECT_DOUBLE_EQ(p->fov_h_deg, d.fov_h_deg);
    EXPECT_DOUBLE_EQ(p->lens.k2, d.lens.k2);
    EXPECT_DOUBLE_EQ(p->acuity.slope, d.acuity.slope);
    // An empty file is the default profile.
    auto empty = parseHmdProfile("", "empty.toml");
    ASSERT_TRUE(empty.ok()) << empty.error();
    EXPECT_EQ(empty->width_px, d.width_px);
}

TEST(ParseHmdProfile, RoundTripsWhenWrittenByHmdProfileToToml) {
    auto p = parseHmdProfile(kFullProfile, "full.toml");
    ASSERT_TRUE(p.ok());
    auto q = parseHmdProfile(hmdProfileToToml(*p), "again.toml");
    ASSERT_TRUE(q.ok()) << q.error();
    EXPECT_EQ(q->name, p->name);
    EXPECT_EQ(q->width_px, p->width_px);
    EXPECT_EQ(q->height_px, p->height_px);
    EXPECT_DOUBLE_EQ(q->refresh_hz, p->refresh_hz);
    EXPECT_DOUBLE_EQ(q->fov_h_deg, p->fov_h_deg);
    EXPECT_DOUBLE_EQ(q->fov_v_deg, p->fov_v_deg);
    EXPECT_DOUBLE_EQ(q->lens.k1, p->lens.k1);
    EXPECT_DOUBLE_EQ(q->lens.chroma_blue_scale, p->lens.chroma_blue_scale);
    EXPECT_DOUBLE_EQ(q->acuity.omega0_deg, p->acuity.omega0_deg);
    EXPECT_DOUBLE_EQ(q->acuity.slope, p->acuity.slope);
    // A name with quotes, backslashes and control characters is escaped, not written raw (found
    // by toml_fuzz).
    HmdProfile odd = *p;
    odd.name = "a\\b \"q\" \\e-6\ttab\nline\x7f";
    auto back = parseHmdProfile(hmdProfileToToml(odd), "odd.toml");
    ASSERT_TRUE(back.ok()) << back.error();
    EXPECT_EQ(back->name, odd.name);
    // The low-res profile survives the same trip.
    auto low = parseHmdProfile(hmdProfileToToml(lowResHmdProfile()), "low.toml");
    ASSERT_TRUE(low.ok()) << low.error();
    EXPECT_EQ(low->width_px, 1280);
    EXPECT_EQ(low->height_px, 1600);
}

struct BadProfile {
    const char* text;
    const char* must_mention;
};

TEST(ParseHmdProfile, FailsWithKeyInMessageWhenFileIsBad) {
    const BadProfile cases[] = {
        {"[display\nwidth_px = 3\n", "bad.toml:1"},                // malformed
        {"[display]\nwidth_px = \n", "bad.toml:2"},                // malformed value
        {"[display]\nwidht_px = 1920\n", "display.widht_px"},      // unknown key
        {"[optics]\nipd_mm = 63\n", "optics"},                     // unknown section
        {"colour = \"red\"\n", "colour"},                          // unknown top-level key
        {"[display]\nwidth_px = 0\n", "display.width_px"},         // width 0
        {"[display]\nheight_px = -1080\n", "display.height_px"},   // negative size
        {"[display]\nwidth_px = 1920.5\n", "display.width_px"},    // fractional pixels
        {"[display]\nrefresh_hz = 0\n", "display.refresh_hz"},     // no refresh
        {"[fov]\nhorizontal_deg = -100\n", "fov.horizontal_deg"},  // negative fov
        {"[fov]\nvertical_deg = 180\n", "fov.vertical_deg"},       // beyond 170
        {"[fov]\nvertical_deg = \"wide\"\n", "fov.vertical_deg"},  // string for number
        {"[lens]\nk1 = \"0.2\"\n", "lens.k1"},                     // string for number
        {"[lens]\nchroma_red_scale = 2.0\n", "lens.chroma_red_scale"},
        {"[acuity]\nomega0_deg = 0\n", "acuity.omega0_deg"},
        {"[acuity]\nslope = -0.01\n", "acuity.slope"},
        {"[acuity]\nslope = nan\n", "acuity.slope"},
        {"name = 7\n", "name"},
    };
    for (const auto& c : cases) {
        auto p = parseHmdProfile(c.text, "bad.toml");
        ASSERT_FALSE(p.ok()) << c.text;
        EXPECT_THAT(p.error(), HasSubstr(c.must_mention)) << c.text;
        EXPECT_THAT(p.error(), HasSubstr("bad.toml")) << c.text;
    }
}

// Reported to the lead: a plain value where a section belongs is silently ignored, because
// A value where a section belongs (`fov = 100`, `display = 3`) is an error, not a silent
// default profile (found by this suite; fixed).
TEST(ParseHmdProfile, FailsWhenValueStandsWhereSectionBelongs) {
    for (const char* text : {"display = 3\n", "fov = 100\n", "acuity = \"sharp\"\n"}) {
        auto p = parseHmdProfile(text, "bad.toml");
        EXPECT_FALSE(p.ok()) << text;
    }
}

TEST(ParseHmdProfile, ReportsEveryProblemWhenFileHasSeveral) {
    auto p = parseHmdProfile("[display]\nwidth_px = 0\n[fov]\nhorizontal_deg = -3\nfoo = 1\n",
                             "multi.toml");
    ASSERT_FALSE(p.ok());
    EXPECT_THAT(p.error(), HasSubstr("display.width_px"));
    EXPECT_THAT(p.error(), HasSubstr("fov.horizontal_deg"));
    EXPECT_THAT(p.error(), HasSubstr("fov.foo"));
}

TEST(HmdProfileByName, ReturnsBuiltInProfilesWhenNamed) {
    auto d = hmdProfileByName("default");
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->width_px, 1920);
    EXPECT_EQ(d->height_px, 2160);
    EXPECT_DOUBLE_EQ(d->refresh_hz, 90.0);
    EXPECT_NEAR(d->fov_h_deg, 100.0, 5.0);
    EXPECT_NEAR(d->fov_v_deg, 110.0, 5.0);
    EXPECT_DOUBLE_EQ(d->acuity.omega0_deg, 1.0 / 48.0);
    EXPECT_DOUBLE_EQ(d->acuity.slope, 0.0275);
    for (const char* name : {"low", "1280x1600"}) {
        auto l = hmdProfileByName(name);
        ASSERT_TRUE(l.ok()) << name;
        EXPECT_EQ(l->width_px, 1280);
        EXPECT_EQ(l->height_px, 1600);
    }
    auto h = hmdProfileByName("1920x2160");
    ASSERT_TRUE(h.ok());
    EXPECT_EQ(h->width_px, 1920);
}

TEST(HmdProfileByName, LoadsFileWhenGivenPath) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("qvr_foveation_profile_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto path = dir / "mine.toml";
    {
        std::ofstream out(path);
        out << kFullProfile;
    }
    auto p = hmdProfileByName(path.string());
    ASSERT_TRUE(p.ok()) << p.error();
    EXPECT_EQ(p->width_px, 1440);
    auto q = loadHmdProfile(path.string());
    ASSERT_TRUE(q.ok());
    EXPECT_EQ(q->name, "test-hmd");
    {
        std::ofstream out(path);
        out << "[display]\nwidth_px = 0\n";
    }
    auto bad = hmdProfileByName(path.string());
    ASSERT_FALSE(bad.ok());
    EXPECT_THAT(bad.error(), HasSubstr("mine.toml"));
    EXPECT_THAT(bad.error(), HasSubstr("display.width_px"));
    std::filesystem::remove_all(dir);
}

// A profile file that sets nothing would be the default profile in disguise: refused, while the
// same file with one field loads.
TEST(LoadHmdProfile, RefusesAFileThatSetsNoField) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("qvr_foveation_empty_profile_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto path = dir / "empty.toml";
    for (const char* text : {"", "# nothing\n", "name = \"only a name\"\n", "[display]\n[fov]\n"}) {
        {
            std::ofstream out(path);
            out << text;
        }
        auto p = loadHmdProfile(path.string());
        ASSERT_FALSE(p.ok()) << "accepted: " << text;
        EXPECT_THAT(p.error(), HasSubstr("empty.toml"));
        EXPECT_THAT(p.error(), HasSubstr("sets no field"));
        EXPECT_FALSE(hmdProfileByName(path.string()).ok());
    }
    {
        std::ofstream out(path);
        out << "[display]\nrefresh_hz = 72\n";
    }
    auto p = loadHmdProfile(path.string());
    ASSERT_TRUE(p.ok()) << p.error();
    EXPECT_DOUBLE_EQ(p->refresh_hz, 72.0);
    std::filesystem::remove_all(dir);
}

TEST(HmdProfileByName, FailsWithPathWhenFileIsMissing) {
    auto p = hmdProfileByName("/nonexistent/dir/hmd.toml");
    ASSERT_FALSE(p.ok());
    EXPECT_THAT(p.error(), HasSubstr("/nonexistent/dir/hmd.toml"));
    auto typo = hmdProfileByName("lowres");
    ASSERT_FALSE(typo.ok());
    EXPECT_THAT(typo.error(), HasSubstr("lowres"));
}

TEST(HmdProfile, MatchesPinholeClosedFormsWhenComputingFocalAndPixelAngle) {
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()}) {
        const double fx = (p.width_px / 2.0) / std::tan(p.fov_h_deg / 2.0 / kDeg);
        const double fy = (p.height_px / 2.0) / std::tan(p.fov_v_deg / 2.0 / kDeg);
        EXPECT_NEAR(p.focalXPx(), fx, 1e-9 * fx);
        EXPECT_NEAR(p.focalYPx(), fy, 1e-9 * fy);
        const double omega_star = std::max(std::atan(1.0 / fx), std::atan(1.0 / fy)) * kDeg;
        EXPECT_NEAR(p.pixelAngleDeg(), omega_star, 1e-12);
        // A pixel subtends between 0.03° and 0.15° on these displays.
        EXPECT_GT(p.pixelAngleDeg(), 0.03);
        EXPECT_LT(p.pixelAngleDeg(), 0.15);
    }
}

TEST(HmdProfile, ScalesByAcuityOverPixelAngleWhenAboveOne) {
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()}) {
        const double omega_star = p.pixelAngleDeg();
        for (double e = 0.0; e <= 90.0; e += 0.5) {
            const double omega = p.acuity.slope * e + p.acuity.omega0_deg;
            EXPECT_NEAR(p.acuity.marDeg(e), omega, 1e-15);
            EXPECT_NEAR(p.scaleAt(e), std::max(1.0, omega / omega_star), 1e-12) << e;
            EXPECT_GE(p.scaleAt(e), 1.0);
        }
        // The fovea's MAR is finer than a pixel: no down-sampling at e = 0.
        EXPECT_DOUBLE_EQ(p.scaleAt(0.0), 1.0);
    }
}

}  // namespace
}  // namespace qvr
