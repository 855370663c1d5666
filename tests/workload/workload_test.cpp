// Per-frame workload helpers: ring sums with a fractional ring, log-log bits-per-pixel
// interpolation, periphery bytes of a plan, and the invariants validateTrace enforces.
#include "qvr/workload/workload.h"

#include <cmath>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace qvr {
namespace {

using ::testing::HasSubstr;

TEST(SumWithinDeg, CountsSplitRingInProportionWhenEccentricityIsFractional) {
    const std::vector<double> rings = {1, 2, 4, 8};
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, 0.0), 0.0);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, -3.0), 0.0);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, 0.25), 0.25);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, 1.0), 1.0);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, 2.5), 1 + 2 + 0.5 * 4);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, 4.0), 15.0);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 1.0, 40.0), 15.0);  // beyond the last ring
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 2.0, 3.0), 1 + 0.5 * 2);
    EXPECT_DOUBLE_EQ(sumWithinDeg(rings, 0.5, 0.75), 1 + 0.5 * 2);
    EXPECT_DOUBLE_EQ(sumWithinDeg({}, 1.0, 5.0), 0.0);
    EXPECT_DOUBLE_EQ(sumTotal(rings), 15.0);
    EXPECT_DOUBLE_EQ(sumTotal({}), 0.0);
}

TEST(SumWithinDeg, MatchesNumericIntegralWhenRingsAreRandom) {
    // Each ring's count spread uniformly over its width: integrate the density numerically.
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 50; ++trial) {
        const double ring_deg = 0.25 + 2.0 * u(rng);
        std::vector<double> rings(20);
        for (double& r : rings)
            r = 1000.0 * u(rng);
        const double e = 25.0 * ring_deg * u(rng);
        double integral = 0.0;
        constexpr int kSteps = 200000;
        const double de = e / kSteps;
        for (int i = 0; i < kSteps; ++i) {
            const size_t k = static_cast<size_t>(std::floor((i + 0.5) * de / ring_deg));
            if (k < rings.size())
                integral += rings[k] / ring_deg * de;
        }
        EXPECT_NEAR(sumWithinDeg(rings, ring_deg, e), integral, 1e-3 * sumTotal(rings))
            << "ring_deg " << ring_deg << " e " << e;
    }
}

WorkloadHeader headerWithScales(std::vector<double> scales) {
    WorkloadHeader h;
    h.ring_deg = 1.0;
    h.rings = 60;
    h.scales = std::move(scales);
    return h;
}

TEST(BitsPerPixelAt, InterpolatesLogLogWhenBetweenScales) {
    const WorkloadHeader h = headerWithScales({1, 2, 4, 8});
    WorkloadFrame f;
    f.bits_per_pixel = {0.5, 0.8, 1.3, 2.0};
    // At the knots: the stored values.
    for (size_t i = 0; i < h.scales.size(); ++i)
        EXPECT_NEAR(bitsPerPixelAt(h, f, h.scales[i]), f.bits_per_pixel[i], 1e-12);
    // The geometric midpoint of two scales gets the geometric mean of their bits.
    EXPECT_NEAR(bitsPerPixelAt(h, f, std::sqrt(2.0)), std::sqrt(0.5 * 0.8), 1e-12);
    EXPECT_NEAR(bitsPerPixelAt(h, f, std::sqrt(32.0)), std::sqrt(1.3 * 2.0), 1e-12);
    // A power law b·s^γ is reproduced exactly everywhere in range.
    WorkloadFrame power;
    for (double s : h.scales)
        power.bits_per_pixel.push_back(0.6 * std::pow(s, 0.7));
    for (double s = 1.0; s <= 8.0; s += 0.01)
        EXPECT_NEAR(bitsPerPixelAt(h, power, s), 0.6 * std::pow(s, 0.7), 1e-12) << s;
}

TEST(BitsPerPixelAt, HoldsEndValuesWhenOutsideScales) {
    const WorkloadHeader h = headerWithScales({1.5, 3, 6});
    WorkloadFrame f;
    f.bits_per_pixel = {0.4, 0.9, 1.7};
    EXPECT_DOUBLE_EQ(bitsPerPixelAt(h, f, 1.0), 0.4);
    EXPECT_DOUBLE_EQ(bitsPerPixelAt(h, f, 0.01), 0.4);
    EXPECT_DOUBLE_EQ(bitsPerPixelAt(h, f, 6.0), 1.7);
    EXPECT_DOUBLE_EQ(bitsPerPixelAt(h, f, 1000.0), 1.7);
    // A single scale is a constant.
    const WorkloadHeader one = headerWithScales({2});
    WorkloadFrame g;
    g.bits_per_pixel = {0.7};
    EXPECT_DOUBLE_EQ(bitsPerPixelAt(one, g, 1.0), 0.7);
    EXPECT_DOUBLE_EQ(bitsPerPixelAt(one, g, 9.0), 0.7);
}

TEST(BitsPerPixelAt, StaysBetweenNeighboursWhenAValueIsZero) {
    // log(0) is undefined; the value must still be finite and between the two knots.
    const WorkloadHeader h = headerWithScales({1, 4});
    WorkloadFrame f;
    f.bits_per_pixel = {0.0, 1.0};
    for (double s = 1.0; s <= 4.0; s += 0.1) {
        const double b = bitsPerPixelAt(h, f, s);
        EXPECT_TRUE(std::isfinite(b));
        EXPECT_GE(b, 0.0);
        EXPECT_LE(b, 1.0);
    }
}

TEST(PeripheryBytes, SendsBothEyesOfEachLayerWhenPlanHasThem) {
    const WorkloadHeader h = headerWithScales({1, 2, 4, 8});
    WorkloadFrame f;
    f.bits_per_pixel = {0.5, 0.8, 1.3, 2.0};
    LayerPlan plan;
    plan.middle_pixels = 10'000;
    plan.outer_pixels = 3'000;
    plan.s1 = 2.0;
    plan.s2 = 8.0;
    const PeripheryBytes b = peripheryBytes(h, f, plan);
    EXPECT_DOUBLE_EQ(b.middle, 2.0 * 10'000 * 0.8 / 8.0);
    EXPECT_DOUBLE_EQ(b.outer, 2.0 * 3'000 * 2.0 / 8.0);
    EXPECT_DOUBLE_EQ(b.total(), b.middle + b.outer);
    plan.middle_pixels = 0;
    plan.outer_pixels = 0;
    EXPECT_EQ(peripheryBytes(h, f, plan).total(), 0.0);
}

WorkloadTrace validTrace() {
    WorkloadTrace t;
    t.header = headerWithScales({1, 2, 4});
    for (int i = 0; i < 3; ++i) {
        WorkloadFrame f;
        f.index = i;
        f.time_ms = 11.0 * i;
        f.triangles_per_ring.assign(60, 100.0);
        f.pixels_per_ring.assign(60, 1000.0);
        f.bits_per_pixel = {0.5, 0.7, 0.9};
        f.static_split = {10.0, 0.5, 100.0, 50.0};
        t.frames.push_back(f);
    }
    return t;
}

TEST(ValidateTrace, AcceptsWhenTraceIsWellFormed) {
    EXPECT_TRUE(validateTrace(validTrace()).ok());
    WorkloadTrace equal_times = validTrace();
    equal_times.frames[1].time_ms = equal_times.frames[0].time_ms;  // non-decreasing is fine
    EXPECT_TRUE(validateTrace(equal_times).ok());
}

TEST(ValidateTrace, RejectsWithReasonWhenAnInvariantIsBroken) {
    struct Case {
        const char* what;
        void (*breakIt)(WorkloadTrace&);
    };
    const Case cases[] = {
        {"ring_deg", [](WorkloadTrace& t) { t.header.ring_deg = 0.0; }},
        {"ring_deg", [](WorkloadTrace& t) { t.header.ring_deg = std::nan(""); }},
        {"rings", [](WorkloadTrace& t) { t.header.rings = 0; }},
        {"rings", [](WorkloadTrace& t) { t.header.rings = kMaxRings + 1; }},
        {"45", [](WorkloadTrace& t) { t.header.ring_deg = 0.5; }},  // only 30° of rings
        {"scales", [](WorkloadTrace& t) { t.header.scales.clear(); }},
        {"scale",
         [](WorkloadTrace& t) {
             t.header.scales = {0.5, 2, 4};
         }},
        {"increasing",
         [](WorkloadTrace& t) {
             t.header.scales = {1, 4, 2};
         }},
        {"increasing",
         [](WorkloadTrace& t) {
             t.header.scales = {1, 2, 2};
         }},
        {"frame 1", [](WorkloadTrace& t) { t.frames[1].triangles_per_ring.pop_back(); }},
        {"frame 2", [](WorkloadTrace& t) { t.frames[2].pixels_per_ring.push_back(1.0); }},
        {"frame 0", [](WorkloadTrace& t) { t.frames[0].bits_per_pixel.pop_back(); }},
        {"non-negative", [](WorkloadTrace& t) { t.frames[1].triangles_per_ring[7] = -1.0; }},
        {"non-negative", [](WorkloadTrace& t) { t.frames[1].pixels_per_ring[0] = INFINITY; }},
        {"non-negative", [](WorkloadTrace& t) { t.frames[2].bits_per_pixel[1] = std::nan(""); }},
        {"time_ms", [](WorkloadTrace& t) { t.frames[2].time_ms = 1.0; }},
        {"time_ms", [](WorkloadTrace& t) { t.frames[0].time_ms = std::nan(""); }},
        {"gaze", [](WorkloadTrace& t) { t.frames[1].gaze.x_deg = 81.0; }},
        {"gaze", [](WorkloadTrace& t) { t.frames[1].gaze.y_deg = std::nan(""); }},
        {"static", [](WorkloadTrace& t) { t.frames[1].static_split.fg_screen_fraction = 1.5; }},
        {"static", [](WorkloadTrace& t) { t.frames[1].static_split.bg_bytes = -1.0; }},
    };
    for (const Case& c : cases) {
        WorkloadTrace t = validTrace();
        c.breakIt(t);
        const Status st = validateTrace(t);
        ASSERT_FALSE(st.ok()) << c.what;
        EXPECT_THAT(st.error(), HasSubstr(c.what));
    }
}

}  // namespace
}  // namespace qvr
