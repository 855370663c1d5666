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

// A cost with a cliff along e1: flat at 1 up to 12°, 50 past it. One line through both sides
// puts 10° at several times its cost and 14° at less than its own; the fit over the positions
// up to a point reads 10°, and what 14° measured floors it.
TEST(WindowedFit, APointReadsThePositionsUpToIt) {
    WindowedFit fit({0.0, 0.0, 0.0}, 32, 1.0);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    for (int i = 0; i < 32; ++i) {
        const double e1 = i % 8 == 7 ? 14.0 : (i % 2 == 0 ? 8.0 : 10.0);
        const double pixels = e1 * e1 * 0.01;  // the fovea's pixels grow with e1
        const double y = (e1 > 12.0 ? 50.0 : 1.0) * (1.0 + u(rng));
        fit.add({1.0, 0.0, pixels}, y, e1);
    }
    auto at = [&](double e1) { return fit.predictAt({1.0, 0.0, e1 * e1 * 0.01}, e1); };
    EXPECT_GT(fit.predict({1.0, 0.0, 1.0}), 5.0) << "the line through both sides";
    EXPECT_LT(fit.predict({1.0, 0.0, 1.96}), 45.0) << "the line through both sides";
    EXPECT_NEAR(at(10.0), 1.0, 0.5);
    EXPECT_NEAR(at(8.0), 1.0, 0.5);
    EXPECT_NEAR(at(6.0), 1.0, 0.5) << "below every position: the fewest that hold enough";
    EXPECT_NEAR(at(14.0), 50.0, 3.0);
    EXPECT_GT(at(20.0), 45.0) << "above every position: no less than the largest measured";
}

// A cost that grows with e1 and carries noise: the fit over the positions up to a point is the
// line there, within the noise.
TEST(WindowedFit, ALinearCostReadsItsLineAtEveryPoint) {
    WindowedFit fit({0.0, 0.0, 0.0}, 32, 1.0);
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.5);
    for (int i = 0; i < 200; ++i) {
        const double e1 = 4.0 + (i % 9);
        fit.add({1.0, 0.0, e1}, 2.0 + e1 + noise(rng), e1);
    }
    for (double e1 = 3.0; e1 <= 14.0; e1 += 0.5)
        EXPECT_NEAR(fit.predictAt({1.0, 0.0, e1}, e1), 2.0 + e1, 0.6) << e1;
}

// Observations without a position, or too few with one, read the whole window's fit.
TEST(WindowedFit, WithoutPositionsAPointReadsTheWholeFit) {
    WindowedFit plain({0.0, 0.0, 0.0}, 32, 1.0);
    for (int i = 0; i < 20; ++i)
        plain.add({1.0, 0.0, i % 2 ? 1.0 : 2.0}, i % 2 ? 1.0 : 3.0);
    EXPECT_DOUBLE_EQ(plain.predictAt({1.0, 0.0, 1.5}, 5.0), plain.predict({1.0, 0.0, 1.5}));
    WindowedFit few({0.0, 0.0, 0.0}, 32, 1.0);
    few.add({1.0, 0.0, 1.0}, 1.0, 10.0);
    few.add({1.0, 0.0, 2.0}, 9.0, 12.0);
    EXPECT_NEAR(few.predictAt({1.0, 0.0, 1.0}, 10.0), few.predict({1.0, 0.0, 1.0}), 1e-9);
}

// One observation the host preempted (a 51 ms render among 0.2 ms ones, a 0.3 headset share)
// tilted the least-squares line so that half the fovea looked 11 ms cheaper, and e1 fled from
// 9.5° to 4.5°. The fit weighs residuals by Huber's rule: one frame moves it little.
TEST(WindowedFit, OneOutlierDoesNotTiltTheFit) {
    WindowedFit fit({0.0, 0.0, 0.0}, 32, 1.0);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> content(0.8, 1.2), noise(-0.02, 0.02);
    auto truth = [](const Vec& x) { return 0.1 + 0.1 * x[1] + 0.05 * x[2]; };
    for (int i = 0; i < 32; ++i) {
        const Vec x{1.0, content(rng), content(rng)};
        fit.add(x, truth(x) + noise(rng) + (i == 20 ? 50.0 : 0.0), 9.5);
    }
    for (const Vec& x : {Vec{1.0, 0.5, 0.5}, Vec{1.0, 1.0, 1.0}, Vec{1.0, 2.0, 2.0}}) {
        EXPECT_NEAR(fit.predict(x), truth(x), 0.1);
        EXPECT_NEAR(fit.predictAt(x, 9.5), truth(x), 0.1);
    }
}

// A frame the host preempted at a position seen once (51 ms among 0.2 ms renders at a 0.3
// headset share) floored every larger position at 51 ms for a window. The positions' means
// are pooled where they fall as the position grows: one frame among 31 cheap ones above it
// floors little.
TEST(WindowedFit, OnePreemptedFrameAtAPositionSeenOnceFloorsLittle) {
    WindowedFit fit({0.0, 0.0, 0.0}, 32, 1.0);
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> noise(-0.02, 0.02);
    fit.add({1.0, 0.0, 0.2}, 51.0, 4.5);
    for (int i = 0; i < 31; ++i)
        fit.add({1.0, 0.0, 0.9}, 0.2 + noise(rng), 9.5);
    EXPECT_LT(fit.predictAt({1.0, 0.0, 0.9}, 9.5), 2.5);
    EXPECT_LT(fit.predictAt({1.0, 0.0, 1.0}, 10.0), 2.5);
}

// A cliff measured a few times and then left (e1 held below it for more than a window) is
// still known: before, once its frames left the window the fit extrapolated the cheap side
// past it and drew e1 back into it every window.
TEST(WindowedFit, ACliffThatLeftTheWindowIsRecalled) {
    WindowedFit fit({0.0, 0.0, 0.0}, 32, 1.0);
    std::mt19937 rng(19);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    auto add = [&](double e1) {
        fit.add({1.0, 0.0, e1 * e1 * 0.01}, (e1 > 12.0 ? 50.0 : 1.0) * (1.0 + u(rng)), e1);
    };
    for (int i = 0; i < 16; ++i)
        add(i % 2 ? 10.0 : 8.0);
    add(14.0);
    add(14.0);
    for (int i = 0; i < 48; ++i)
        add(i % 2 ? 10.0 : 8.0);
    ASSERT_TRUE(fit.highestPosition().has_value());
    EXPECT_DOUBLE_EQ(*fit.highestPosition(), 14.0);
    EXPECT_GT(fit.predictAt({1.0, 0.0, 1.96}, 14.0), 40.0);
    EXPECT_GT(fit.predictAt({1.0, 0.0, 2.56}, 16.0), 40.0);
    EXPECT_NEAR(fit.predictAt({1.0, 0.0, 1.0}, 10.0), 1.0, 0.5);
    // Past kRecalledWindows windows more it is forgotten, and e1 may look again.
    for (int i = 0; i < int(WindowedFit::kRecalledWindows * 32); ++i)
        add(i % 2 ? 10.0 : 8.0);
    EXPECT_DOUBLE_EQ(*fit.highestPosition(), 10.0);
}

}  // namespace
}  // namespace qvr
