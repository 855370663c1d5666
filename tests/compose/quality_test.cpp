// Quality of UCA against the double-precision ground truth (issue 4, paper §4.2): UCA resamples
// each layer once, so it must be at least as good as the two-pass path that resamples twice.
#include "qvr/compose/quality.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "qvr/compose/test_pattern.h"
#include "qvr/compose/uca.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {
namespace {

HmdProfile midProfile() {
    HmdProfile p = defaultHmdProfile();
    p.width_px = 960;
    p.height_px = 1080;
    return p;
}

TEST(ComposeQuality, IdenticalImageHasInfinitePsnrAndUnitSsim) {
    HmdProfile profile = midProfile();
    profile.lens = LensProfile{0.0, 0.0, 1.0, 1.0};
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 15.0);
    const ImageRgba8 full = renderTestPattern(profile.width_px, profile.height_px);
    const ImageRgbD truth = groundTruthWarp(profile, full, Pose{}, Pose{});
    const QualityReport q = measureQuality(profile, plan, Pose{}, Pose{}, full, truth);
    EXPECT_GT(q.all.psnr_db, 100.0);  // the identity map in double leaves ~1e-12 of error
    EXPECT_NEAR(q.all.ssim, 1.0, 1e-6);
    EXPECT_EQ(q.fovea.pixels + q.periphery.pixels, q.all.pixels);
    EXPECT_EQ(q.all.pixels, int64_t{profile.width_px} * profile.height_px);
    // One pixel of shift is visible in both measures.
    ImageRgba8 shifted = full;
    for (int y = 0; y < full.height(); ++y) {
        for (int x = 1; x < full.width(); ++x) {
            for (int c = 0; c < 4; ++c)
                shifted.at(x, y, c) = full.at(x - 1, y, c);
        }
    }
    const QualityReport s = measureQuality(profile, plan, Pose{}, Pose{}, shifted, truth);
    EXPECT_LT(s.all.psnr_db, 30.0);
    EXPECT_LT(s.all.ssim, 0.95);
}

TEST(ComposeQuality, UcaIsAtLeastAsGoodAsTwoPassInFoveaAndPeriphery) {
    const HmdProfile profile = midProfile();
    const LayerPlanner planner(profile);
    const LayerPlan plan = planner.plan({4.0, -2.0}, 15.0);
    const ImageRgba8 full = renderTestPattern(profile.width_px, profile.height_px);
    const Pose render;
    Pose display;
    display.orientation = quatFromEulerDeg({2.0, 1.0, 0.5});
    const LayerFrame frame = makeTestPatternFrame(profile, plan, render, 1, full);
    Compositor c(profile);
    std::array<ImageRgba8, 2> uca, two_pass;
    ASSERT_TRUE(c.compose(frame, display, uca).ok());
    ASSERT_TRUE(c.composeTwoPass(frame, display, two_pass).ok());
    const ImageRgbD truth = groundTruthWarp(profile, full, render, display);
    const QualityReport qu = measureQuality(profile, plan, render, display, uca[0], truth);
    const QualityReport qt = measureQuality(profile, plan, render, display, two_pass[0], truth);
    std::printf("UCA      fovea %.3f dB %.4f  periphery %.3f dB %.4f\n", qu.fovea.psnr_db,
                qu.fovea.ssim, qu.periphery.psnr_db, qu.periphery.ssim);
    std::printf("two-pass fovea %.3f dB %.4f  periphery %.3f dB %.4f\n", qt.fovea.psnr_db,
                qt.fovea.ssim, qt.periphery.psnr_db, qt.periphery.ssim);
    EXPECT_GT(qu.fovea.pixels, 10000);
    EXPECT_GT(qu.periphery.pixels, 10000);
    EXPECT_GE(qu.fovea.psnr_db, qt.fovea.psnr_db - 0.01);
    EXPECT_GE(qu.periphery.psnr_db, qt.periphery.psnr_db);
    EXPECT_GE(qu.fovea.ssim, qt.fovea.ssim - 1e-4);
    EXPECT_GE(qu.periphery.ssim, qt.periphery.ssim);
    // Against the layers' own Eq. 4 in double, only filtering and rounding remain: UCA filters
    // each layer once, the two-pass path twice with an 8-bit buffer between, so UCA must be
    // clearly closer, everywhere.
    const ImageRgbD ideal = layerReferenceWarp(profile, frame, 0, display);
    const QualityReport lu = measureQuality(profile, plan, render, display, uca[0], ideal);
    const QualityReport lt = measureQuality(profile, plan, render, display, two_pass[0], ideal);
    std::printf("vs layers: UCA fovea %.2f periphery %.2f dB; two-pass %.2f %.2f dB\n",
                lu.fovea.psnr_db, lu.periphery.psnr_db, lt.fovea.psnr_db, lt.periphery.psnr_db);
    EXPECT_GT(lu.fovea.psnr_db, 50.0);
    EXPECT_GT(lu.periphery.psnr_db, 50.0);
    EXPECT_GT(lu.fovea.psnr_db, lt.fovea.psnr_db + 1.0);
    EXPECT_GT(lu.periphery.psnr_db, lt.periphery.psnr_db + 1.0);
    EXPECT_GE(lu.periphery.ssim, lt.periphery.ssim);
    // Inside the fovea, clear of the blend band, UCA's only error is float maths and 8-bit
    // rounding: a wrong map or filter would show here first.
    LayerPlan core = plan;
    core.e1_deg = plan.e1_deg - 2.0;
    const QualityReport qc = measureQuality(profile, core, render, display, uca[0], truth);
    EXPECT_GT(qc.fovea.psnr_db, 45.0);
    EXPECT_GT(qc.fovea.ssim, 0.999);
}

}  // namespace
}  // namespace qvr

namespace qvr {
namespace {

TEST(ComposeQualityBands, SplitsThePixelsByBandAndFoveaBeatsOuterOnAFoveatedFrame) {
    HmdProfile profile = defaultHmdProfile();
    profile.width_px = 960;
    profile.height_px = 1080;
    const LayerPlan plan = LayerPlanner(profile).plan({3.0, -2.0}, 12.0);
    ASSERT_LT(plan.e2_deg, plan.cover_deg);  // all four bands exist
    const ImageRgba8 full = renderTestPattern(profile.width_px, profile.height_px);
    const Pose render;
    const LayerFrame frame = makeTestPatternFrame(profile, plan, render, 1, full);
    Compositor c(profile);
    std::array<ImageRgba8, 2> display;
    ASSERT_TRUE(c.compose(frame, render, display).ok());
    const ImageRgbD truth = groundTruthWarp(profile, full, render, render);
    const BandQuality q = measureQualityBands(profile, plan, render, render, display[0], truth);
    std::printf("fovea %.2f dB %.4f  blend %.2f dB  middle %.2f dB  outer %.2f dB %.4f\n",
                q.fovea.psnr_db, q.fovea.ssim, q.blend.psnr_db, q.middle.psnr_db, q.outer.psnr_db,
                q.outer.ssim);
    for (const RegionQuality* r : {&q.fovea, &q.blend, &q.middle, &q.outer})
        EXPECT_GT(r->pixels, 1000);
    EXPECT_EQ(q.fovea.pixels + q.blend.pixels + q.middle.pixels + q.outer.pixels, q.all.pixels);
    // The full-resolution fovea is close to the truth; the 1/s2² outer layer is not.
    EXPECT_GT(q.fovea.psnr_db, q.outer.psnr_db + 3.0);
    EXPECT_GT(q.fovea.ssim, q.outer.ssim);
    EXPECT_GT(q.blend_deg[0], 0.0);
    // The bins cover the same pixels, in increasing eccentricity.
    int64_t binned = 0;
    double last = -1.0;
    for (const BandQuality::Bin& b : q.by_eccentricity) {
        binned += b.q.pixels;
        EXPECT_GT(b.center_deg, last);
        last = b.center_deg;
    }
    EXPECT_EQ(binned, q.all.pixels);
    EXPECT_GT(q.by_eccentricity.front().q.psnr_db, q.by_eccentricity.back().q.psnr_db);
}

}  // namespace
}  // namespace qvr
