// The calibration's cost fits (sim/cost_fit.h) against laws known in closed form.
#include "qvr/sim/cost_fit.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

namespace qvr {
namespace {

// Layers over 3 kpx … 300 kpx and 1 … 60 ktri, uncorrelated enough to separate the slopes.
std::vector<CostSample> layerGrid(const std::function<double(double, double)>& law) {
    std::vector<CostSample> s;
    for (double px : {3e3, 1e4, 3e4, 1e5, 3e5})
        for (double tri : {1e3, 5e3, 2e4, 6e4})
            s.push_back({law(px, tri), px, tri, false});
    return s;
}

TEST(CostFit, RecoversAnExactLinearLaw) {
    const auto s =
        layerGrid([](double px, double tri) { return 0.4 + 35.0 * px * 1e-6 + 0.13 * tri * 1e-3; });
    const PartCost c = fitPartCost(s, {.use_px = true, .use_tri = true});
    EXPECT_NEAR(c.base_ms, 0.4, 1e-9);
    EXPECT_NEAR(c.ms_per_mpx, 35.0, 1e-7);
    EXPECT_NEAR(c.ms_per_ktri, 0.13, 1e-9);
    EXPECT_EQ(c.power_coef_ms, 0.0);
    EXPECT_EQ(c.full_frame_scale, 1.0);
    EXPECT_NEAR(costResidualRmsPct(s, c), 0.0, 1e-6);
}

// The oa_dm5 server case of the version-7 calibration: the best line has a negative intercept.
// Clamping it to 0 and keeping the slopes overcharged every small layer by the lost intercept;
// the fit must refit through the origin instead.
TEST(CostFit, ANegativeInterceptIsRefittedThroughTheOrigin) {
    const auto s =
        layerGrid([](double px, double tri) { return 20.0 * px * 1e-6 + 0.2 * tri * 1e-3; });
    std::vector<CostSample> shifted = s;
    for (CostSample& x : shifted)  // a concave law: a line through it has a negative intercept
        x.ms = std::pow(x.ms, 1.3);
    const PartCost c = fitPartCost(shifted, {.use_px = true, .use_tri = true});
    EXPECT_EQ(c.base_ms, 0.0);
    EXPECT_GE(c.ms_per_mpx, 0.0);
    EXPECT_GE(c.ms_per_ktri, 0.0);
    // The smallest layers are not charged a lost intercept: their mean signed error is what a
    // line through the origin leaves (+4%), not the +42% the old fit left here (its
    // unconstrained line, −0.28 ms + 28.9·Mpx + 0.33·ktri, with the intercept clamped to 0).
    double err = 0.0;
    int n = 0;
    for (const CostSample& x : shifted)
        if (x.pixels <= 1e4) {
            err += (c.at(x.pixels, x.triangles) - x.ms) / x.ms;
            ++n;
        }
    std::printf("smallest layers: mean signed error %+.1f%%, RMS %.1f%%\n", 100.0 * err / n,
                costResidualRmsPct(shifted, c));
    EXPECT_LT(std::fabs(err / n), 0.15);
}

TEST(CostFit, ThePowerLawIsKeptWhereItFitsBetter) {
    const auto law = [](double px, double tri) {
        return 2.0 * std::pow(px * 1e-6, 0.5) * std::pow(tri * 1e-3, 0.7);
    };
    const auto s = layerGrid(law);
    const PartCost lin = fitPartCost(s, {.use_px = true, .use_tri = true, .allow_power = false});
    const PartCost c = fitPartCost(s, {.use_px = true, .use_tri = true, .allow_power = true});
    EXPECT_NEAR(c.power_coef_ms, 2.0, 1e-9);
    EXPECT_NEAR(c.px_exponent, 0.5, 1e-9);
    EXPECT_NEAR(c.tri_exponent, 0.7, 1e-9);
    EXPECT_NEAR(c.at(2e5, 3e4), law(2e5, 3e4), 1e-9);
    EXPECT_GT(costResidualRmsPct(s, lin), 5.0);
    EXPECT_NEAR(costResidualRmsPct(s, c), 0.0, 1e-6);
    // And a linear law stays linear when the power law is allowed.
    const auto lin_s =
        layerGrid([](double px, double tri) { return 0.3 + 40.0 * px * 1e-6 + 0.1 * tri * 1e-3; });
    EXPECT_EQ(
        fitPartCost(lin_s, {.use_px = true, .use_tri = true, .allow_power = true}).power_coef_ms,
        0.0);
}

TEST(CostFit, WholeFramesGetTheirOwnScaleAndDoNotMoveTheLaw) {
    const auto law = [](double px, double tri) {
        return 0.4 + 35.0 * px * 1e-6 + 0.13 * tri * 1e-3;
    };
    auto s = layerGrid(law);
    const double eye_px = 4147200.0;
    for (double tri : {2.0e5, 2.2e5, 2.4e5})
        s.push_back({0.85 * law(eye_px, tri), eye_px, tri, true});
    const PartCost c = fitPartCost(s, {.use_px = true, .use_tri = true});
    EXPECT_NEAR(c.ms_per_mpx, 35.0, 1e-7);
    EXPECT_NEAR(c.full_frame_scale, 0.85, 1e-9);
    EXPECT_NEAR(c.atFullFrame(eye_px, 2.2e5), 0.85 * law(eye_px, 2.2e5), 1e-6);
    EXPECT_NEAR(costResidualRmsPct(s, c), 0.0, 1e-6);
}

TEST(CostFit, OnlyWholeFramesOrNoSamples) {
    const std::vector<CostSample> full = {{100.0, 4e6, 1e5, true}, {120.0, 4e6, 2e5, true}};
    const PartCost c = fitPartCost(full, {.use_px = false, .use_tri = true});
    EXPECT_EQ(c.full_frame_scale, 1.0);
    EXPECT_NEAR(c.at(4e6, 1e5), 100.0, 1e-6);
    EXPECT_NEAR(c.at(4e6, 2e5), 120.0, 1e-6);
    const PartCost none = fitPartCost({}, {.use_px = true, .use_tri = true, .allow_power = true});
    EXPECT_EQ(none.at(1e5, 1e4), 0.0);
}

// llvmpipe's fovea pass follows the fragments it shades (the overdraw), not its pixels: two poses
// with the same pixels and triangles measured 2× apart (calibration version 16). Samples whose
// time is a law of fragments and triangles, with depth complexity varying 1.5–8× independently
// of the pixels: the fragments' law is recovered exactly, where the pixels' law cannot be.
TEST(CostFit, TheFragmentsLawRecoversOverdrawThePixelsCannot) {
    std::vector<CostSample> s;
    const double depth[] = {1.5, 4.0, 8.0, 2.5};
    int k = 0;
    double frags = 0.0, px_sum = 0.0;
    for (double px : {3e3, 1e4, 3e4, 1e5, 3e5})
        for (double tri : {1e3, 5e3, 2e4, 6e4}) {
            const double f = px * depth[k++ % 4];
            frags += f;
            px_sum += px;
            s.push_back({0.2 + 18.0 * f * 1e-6 + 0.05 * tri * 1e-3, px, tri, false, f});
        }
    const PartCost c = fitPartCost(s, {.use_px = true, .use_tri = true, .use_frag = true});
    EXPECT_NEAR(c.base_ms, 0.2, 1e-9);
    EXPECT_NEAR(c.ms_per_mfrag, 18.0, 1e-7);
    EXPECT_NEAR(c.ms_per_ktri, 0.05, 1e-9);
    EXPECT_EQ(c.ms_per_mpx, 0.0);
    EXPECT_NEAR(c.frag_per_px, frags / px_sum, 1e-12);
    EXPECT_NEAR(costResidualRmsPct(s, c), 0.0, 1e-6);
    const PartCost px_law = fitPartCost(s, {.use_px = true, .use_tri = true, .allow_power = true});
    EXPECT_GT(costResidualRmsPct(s, px_law), 20.0);
    // A pass whose fragments are not known is charged the samples' mean depth complexity.
    EXPECT_NEAR(c.at(1e5, 2e4), 0.2 + 18.0 * 1e5 * c.frag_per_px * 1e-6 + 0.05 * 20.0, 1e-9);
    EXPECT_NEAR(c.at(1e5, 2e4, 6e5), 0.2 + 18.0 * 0.6 + 0.05 * 20.0, 1e-9);
    // One sample without a count: the pixels' law, as before version 16.
    s.back().fragments = -1.0;
    const PartCost mixed = fitPartCost(s, {.use_px = true, .use_tri = true, .use_frag = true});
    EXPECT_EQ(mixed.ms_per_mfrag, 0.0);
    EXPECT_GT(mixed.ms_per_mpx, 0.0);
}

// The bits law b·s^γ: exact samples give it back, and noisy ones give the b whose total is the
// samples' total (the mean), not the geometric mean a log fit alone gives.
TEST(BitsLaw, RecoversAnExactLawAndItsTotal) {
    std::vector<BitsSample> s;
    for (double scale : {1.0, 2.5, 4.0, 7.0, 12.0})
        for (double px : {2e4, 9e4})
            s.push_back({scale, px, px * 0.3 * std::pow(scale, 0.4)});
    const BitsLaw law = fitBitsLaw(s);
    EXPECT_NEAR(law.bits_per_px_at_1, 0.3, 1e-9);
    EXPECT_NEAR(law.scale_exponent, 0.4, 1e-9);
    EXPECT_NEAR(law.geometric_b, 0.3, 1e-9);
}

TEST(BitsLaw, NoisyFramesKeepTheirMeanNotTheirGeometricMean) {
    // Every scale sees P-frames at 0.7x and 1.5x the law alike: the mean is 1.1x, the geometric
    // mean sqrt(1.05) = 1.0247x.
    std::vector<BitsSample> s;
    double total = 0.0;
    for (double scale : {1.5, 3.0, 6.0, 10.0})
        for (double noise : {0.7, 1.5}) {
            const double px = 5e4;
            s.push_back({scale, px, px * 0.25 * std::pow(scale, 0.3) * noise});
            total += s.back().bits;
        }
    const BitsLaw law = fitBitsLaw(s);
    EXPECT_NEAR(law.scale_exponent, 0.3, 1e-9);
    EXPECT_NEAR(law.geometric_b, 0.25 * std::sqrt(0.7 * 1.5), 1e-9);
    EXPECT_NEAR(law.bits_per_px_at_1, 0.25 * 1.1, 1e-9);
    double predicted = 0.0;
    for (const BitsSample& b : s)
        predicted += b.pixels * law.bits_per_px_at_1 * std::pow(b.scale, law.scale_exponent);
    EXPECT_NEAR(predicted, total, 1e-6 * total);
}

TEST(BitsLaw, TooFewUsableSamplesGiveNoLaw) {
    EXPECT_EQ(fitBitsLaw({}).bits_per_px_at_1, 0.0);
    // Empty frames and empty layers do not count.
    const BitsLaw law = fitBitsLaw({{2.0, 1e4, 3e3}, {3.0, 0.0, 100.0}, {4.0, 1e4, 0.0}});
    EXPECT_EQ(law.bits_per_px_at_1, 0.0);
    EXPECT_EQ(law.scale_exponent, 0.0);
}

}  // namespace
}  // namespace qvr
