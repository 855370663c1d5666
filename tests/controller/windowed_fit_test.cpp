// WindowedFit (LIWC's runtime cost fits, docs/LIWC.md "Fits"): ridge least squares over a window
// of observations, pulled toward the previous fit, with coefficients kept non-negative.
#include "qvr/controller/windowed_fit.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace qvr {
namespace {

using Vec = WindowedFit::Vec;

double dot(const Vec& a, const Vec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void expectFinite(const WindowedFit& f) {
    for (double v : f.theta())
        ASSERT_TRUE(std::isfinite(v));
}

TEST(WindowedFit, RecoversALinearModelWhenSamplesAreNoisy) {
    // y = 0.8 + 2.5·a + 0.6·b + N(0, 0.05²), a and b independent: the fit starts far off.
    const Vec truth{0.8, 2.5, 0.6};
    WindowedFit fit({0.0, 10.0, 0.1}, 64);
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> a(0.0, 3.0), b(0.0, 5.0);
    std::normal_distribution<double> noise(0.0, 0.05);
    for (int i = 0; i < 400; ++i) {
        const Vec x{1.0, a(rng), b(rng)};
        fit.add(x, dot(truth, x) + noise(rng));
        expectFinite(fit);
    }
    EXPECT_EQ(fit.size(), 64u);
    EXPECT_NEAR(fit.theta()[0], truth[0], 0.06);
    EXPECT_NEAR(fit.theta()[1], truth[1], 0.03);
    EXPECT_NEAR(fit.theta()[2], truth[2], 0.02);
    for (const Vec& x : {Vec{1.0, 0.5, 1.0}, Vec{1.0, 2.5, 4.0}})
        EXPECT_NEAR(fit.predict(x), dot(truth, x), 0.05);
}

// An input held at zero (a layer that has no pixels, e1 beyond the field): its coefficient keeps
// its value exactly, and the others are still learned.
TEST(WindowedFit, KeepsTheCoefficientOfAnInputHeldAtZero) {
    for (double ridge : {1.0, 0.5, 4.0}) {
        WindowedFit fit({1.0, 1.0, 1.0}, 32, ridge);
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> a(0.5, 2.0);
        for (int i = 0; i < 200; ++i) {
            const Vec x{1.0, a(rng), 0.0};
            fit.add(x, 2.0 + 3.0 * x[1]);
        }
        expectFinite(fit);
        EXPECT_DOUBLE_EQ(fit.theta()[2], 1.0) << "ridge " << ridge;
        EXPECT_NEAR(fit.theta()[0], 2.0, 1e-3) << "ridge " << ridge;
        EXPECT_NEAR(fit.theta()[1], 3.0, 1e-3) << "ridge " << ridge;
    }
}

// An input held at a non-zero constant is collinear with the intercept: least squares alone is
// singular. The fit stays finite, learns the excited directions (the prediction where the data
// are, the varying input's slope) and leaves the unexcited combination where it started. In the
// fit's units (each input scaled by its root mean square) the pull toward the previous fit is
// isotropic, so the unexcited combination is θ0 − c·θ2 for an input held at c > 0.
TEST(WindowedFit, StaysFiniteAndKeepsTheUnexcitedCombinationWhenAnInputIsConstant) {
    const double c = 0.5;
    WindowedFit fit({1.0, 1.0, 1.0}, 32);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> a(0.0, 2.0);
    std::normal_distribution<double> noise(0.0, 0.02);
    // Truth: 2 + 3·a + 4·c, i.e. θ0 + c·θ2 = 4.
    Vec after_half{};
    for (int i = 0; i < 2000; ++i) {
        const Vec x{1.0, a(rng), c};
        fit.add(x, 2.0 + 3.0 * x[1] + 4.0 * c + noise(rng));
        expectFinite(fit);
        for (double v : fit.theta())
            ASSERT_LT(std::fabs(v), 100.0) << "observation " << i;
        if (i == 999)
            after_half = fit.theta();
    }
    const Vec& t = fit.theta();
    EXPECT_NEAR(t[1], 3.0, 0.02);
    EXPECT_NEAR(t[0] + c * t[2], 4.0, 0.02);
    EXPECT_NEAR(t[0] - c * t[2], 1.0 - c * 1.0, 0.05);
    // No drift along the unexcited direction over another thousand observations.
    for (size_t i = 0; i < 3; ++i)
        EXPECT_NEAR(t[i], after_half[i], 0.05) << i;
}

TEST(WindowedFit, NeverGivesANegativeCoefficient) {
    // y = 5 − 2·a + 1·b: the best non-negative fit drops a and refits the rest. With a and b
    // independent and a uniform on [0, 1], y ≈ (5 − 2·E[a]) + b = 4 + b plus noise from a.
    WindowedFit fit({1.0, 1.0, 1.0}, 200);
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> a(0.0, 1.0), b(0.0, 4.0);
    for (int i = 0; i < 600; ++i) {
        const Vec x{1.0, a(rng), b(rng)};
        fit.add(x, 5.0 - 2.0 * x[1] + x[2]);
        for (double v : fit.theta())
            ASSERT_GE(v, 0.0) << "observation " << i;
    }
    EXPECT_EQ(fit.theta()[1], 0.0);
    EXPECT_NEAR(fit.theta()[0], 4.0, 0.15);
    EXPECT_NEAR(fit.theta()[2], 1.0, 0.05);
    // A model whose intercept is negative (y still positive on average): the intercept is
    // pinned at 0, the slopes stay ≥ 0 and carry the rest.
    WindowedFit neg({0.0, 0.0, 0.0}, 50);
    for (int i = 0; i < 300; ++i) {
        const Vec x{1.0, a(rng), b(rng)};
        neg.add(x, -1.0 + 3.0 * x[1] + 1.0 * x[2]);
        for (double v : neg.theta())
            ASSERT_GE(v, 0.0) << "observation " << i;
    }
    EXPECT_EQ(neg.theta()[0], 0.0);
    EXPECT_GT(neg.theta()[1], 0.5);
    EXPECT_GT(neg.theta()[2], 0.5);
}

TEST(WindowedFit, ForgetsObservationsThatLeftTheWindow) {
    // 100 observations of model A, then model B: once the window holds only B, the fit is B's,
    // with none of A's pull left.
    const Vec model_a{1.0, 2.0, 0.5}, model_b{3.0, 0.5, 1.5};
    const size_t window = 16;
    WindowedFit fit({0.0, 0.0, 0.0}, window);
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> a(0.0, 2.0), b(0.0, 2.0);
    for (int i = 0; i < 100; ++i) {
        const Vec x{1.0, a(rng), b(rng)};
        fit.add(x, dot(model_a, x));
        ASSERT_LE(fit.size(), window);
    }
    for (size_t i = 0; i < 3; ++i)
        EXPECT_NEAR(fit.theta()[i], model_a[i], 1e-3) << i;
    for (size_t n = 1; n <= 4 * window; ++n) {
        const Vec x{1.0, a(rng), b(rng)};
        fit.add(x, dot(model_b, x));
        EXPECT_EQ(fit.size(), window);
    }
    for (size_t i = 0; i < 3; ++i)
        EXPECT_NEAR(fit.theta()[i], model_b[i], 1e-3) << i;
}

TEST(WindowedFit, IgnoresNonFiniteObservations) {
    const Vec truth{0.5, 1.0, 2.0};
    WindowedFit fit({0.0, 0.0, 0.0}, 32);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 40; ++i) {
        const Vec x{1.0, u(rng), u(rng)};
        fit.add(x, dot(truth, x));
    }
    const Vec before = fit.theta();
    const size_t size = fit.size();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    fit.add({1.0, 0.5, 0.5}, nan);
    fit.add({1.0, 0.5, 0.5}, inf);
    fit.add({1.0, 0.5, 0.5}, -inf);
    fit.add({1.0, nan, 0.5}, 1.0);
    fit.add({1.0, 0.5, inf}, 1.0);
    fit.add({-inf, 0.5, 0.5}, 1.0);
    EXPECT_EQ(fit.size(), size);
    for (size_t i = 0; i < 3; ++i)
        EXPECT_EQ(fit.theta()[i], before[i]) << i;
    // Still learning afterwards.
    fit.add({1.0, 0.25, 0.75}, dot(truth, {1.0, 0.25, 0.75}));
    expectFinite(fit);
    EXPECT_NEAR(fit.predict({1.0, 0.5, 0.5}), dot(truth, {1.0, 0.5, 0.5}), 1e-3);
}

}  // namespace
}  // namespace qvr
