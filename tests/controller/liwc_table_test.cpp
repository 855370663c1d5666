// LIWC's table (paper §4.1, §4.3): 2^10 motions × 32 eccentricity buckets of fp16 offsets,
// exactly 64 KB; stored values round to the nearest half float; the fold rule.
#include "qvr/controller/liwc_table.h"

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <gtest/gtest.h>

namespace qvr {
namespace {

// The nearest IEEE binary16 value to v (round to nearest; |v| within the normal/subnormal range),
// computed from the format's spacing rather than by any packing routine.
double nearestHalf(double v) {
    if (v == 0.0)
        return 0.0;
    const double a = std::fabs(v);
    const int exponent = std::max(-14, static_cast<int>(std::floor(std::log2(a))));
    const double ulp = std::ldexp(1.0, exponent - 10);
    return std::copysign(std::nearbyint(a / ulp) * ulp, v);
}

double halfUlp(double v) {
    const double a = std::max(std::fabs(v), std::ldexp(1.0, -14));
    return std::ldexp(1.0, static_cast<int>(std::floor(std::log2(a))) - 10);
}

TEST(LiwcTable, Holds32768EntriesIn64KilobytesWhenSizedAsPaper) {
    EXPECT_EQ(LiwcTable::kEntries, 32768u);
    EXPECT_EQ(LiwcTable::kBytes, 65536u);
    EXPECT_EQ(LiwcTable::kEntries, static_cast<size_t>(kMotionCodes) *
                                       static_cast<size_t>(LiwcTable::kEccentricityBuckets));
    // The storage is one 16-bit word per entry.
    EXPECT_EQ(sizeof(LiwcTable), LiwcTable::kBytes);
}

TEST(LiwcTable, MapsEveryMotionAndBucketToItsOwnEntryWhenIndexing) {
    std::set<size_t> seen;
    for (int m = 0; m < kMotionCodes; ++m)
        for (int b = 0; b < LiwcTable::kEccentricityBuckets; ++b) {
            const size_t i = LiwcTable::indexOf(static_cast<uint16_t>(m), b);
            ASSERT_LT(i, LiwcTable::kEntries);
            seen.insert(i);
        }
    EXPECT_EQ(seen.size(), LiwcTable::kEntries);
}

TEST(LiwcTable, BucketsByThreeDegreesWhenGivenEccentricity) {
    EXPECT_EQ(LiwcTable::bucketOf(0.0), 0);
    EXPECT_EQ(LiwcTable::bucketOf(2.999), 0);
    EXPECT_EQ(LiwcTable::bucketOf(3.0), 1);
    EXPECT_EQ(LiwcTable::bucketOf(5.99), 1);
    EXPECT_EQ(LiwcTable::bucketOf(6.0), 2);
    EXPECT_EQ(LiwcTable::bucketOf(15.0), 5);
    EXPECT_EQ(LiwcTable::bucketOf(92.99), 30);
    EXPECT_EQ(LiwcTable::bucketOf(93.0), 31);
    EXPECT_EQ(LiwcTable::bucketOf(96.0), 31);
    EXPECT_EQ(LiwcTable::bucketOf(1e9), 31);
    EXPECT_EQ(LiwcTable::bucketOf(-4.0), 0);
    EXPECT_EQ(LiwcTable::bucketOf(std::numeric_limits<double>::quiet_NaN()), 0);
    for (double e = 0.0; e < 96.0; e += 0.01) {
        const int b = LiwcTable::bucketOf(e);
        EXPECT_LE(b * LiwcTable::kBucketDeg, e + 1e-12);
        EXPECT_GT((b + 1) * LiwcTable::kBucketDeg, e);
    }
}

// Reported to the lead: bucketOf casts e/3 to int before clamping, so e = +inf or any e above
// about 6.4e9° (beyond INT_MAX buckets) is undefined behaviour and returns INT_MIN on x86-64; the
// negative bucket then aborts in indexOf's check. LIWC itself clamps e1 to ≤ 90° first.
TEST(LiwcTable, BucketsLastWhenEccentricityIsHuge) {
    EXPECT_EQ(LiwcTable::bucketOf(std::numeric_limits<double>::infinity()), 31);
    EXPECT_EQ(LiwcTable::bucketOf(1e10), 31);
}

TEST(LiwcTable, ReadsBackNearestHalfWhenStoringFloat) {
    LiwcTable t;
    t.setOffsetMs(5, 3, 0.1f);
    EXPECT_EQ(t.offsetMs(5, 3), 0.0999755859375f);  // 0x2E66, the nearest half to 0.1
    EXPECT_NE(t.offsetMs(5, 3), 0.1f);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> mant(-1.0, 1.0);
    std::uniform_int_distribution<int> expo(-20, 15);
    for (int i = 0; i < 20000; ++i) {
        const float v = static_cast<float>(std::ldexp(mant(rng), expo(rng)));
        if (std::fabs(v) > 60000.0f)
            continue;
        t.setOffsetMs(17, 9, v);
        const double got = t.offsetMs(17, 9);
        // Exactly the nearest half, except that a tie may go either way.
        EXPECT_LE(std::fabs(got - v), 0.5 * halfUlp(v) + 1e-12) << v;
        if (std::fabs(std::fabs(got - v) - 0.5 * halfUlp(v)) > 1e-3 * halfUlp(v)) {
            EXPECT_EQ(got, nearestHalf(v)) << v;
        }
    }
}

TEST(LiwcTable, KeepsEntriesIndependentWhenOneIsWritten) {
    LiwcTable t;
    for (int m : {0, 1, 511, 1023})
        for (int b : {0, 1, 30, 31})
            EXPECT_EQ(t.offsetMs(static_cast<uint16_t>(m), b), 0.0f);
    t.setOffsetMs(511, 30, 2.5f);
    EXPECT_EQ(t.offsetMs(511, 30), 2.5f);
    EXPECT_EQ(t.offsetMs(511, 29), 0.0f);
    EXPECT_EQ(t.offsetMs(511, 31), 0.0f);
    EXPECT_EQ(t.offsetMs(510, 30), 0.0f);
    EXPECT_EQ(t.offsetMs(512, 30), 0.0f);
    t.clear();
    EXPECT_EQ(t.offsetMs(511, 30), 0.0f);
}

TEST(LiwcTable, FoldsAsOneMinusAlphaOldPlusAlphaDeltaWhenUpdating) {
    LiwcTable t;
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> val(-20.0f, 20.0f);
    std::uniform_real_distribution<float> alpha(0.01f, 1.0f);
    for (int i = 0; i < 5000; ++i) {
        const uint16_t m = static_cast<uint16_t>(i % kMotionCodes);
        const int b = i % LiwcTable::kEccentricityBuckets;
        t.setOffsetMs(m, b, val(rng));
        const double old = t.offsetMs(m, b);
        const float delta = val(rng);
        const float a = alpha(rng);
        t.fold(m, b, delta, a);
        const double expect = (1.0 - a) * old + static_cast<double>(a) * delta;
        EXPECT_LE(std::fabs(t.offsetMs(m, b) - expect), 0.5 * halfUlp(expect) + 1e-6)
            << "old " << old << " delta " << delta << " alpha " << a;
    }
    // α = 1 replaces, and repeated folds of the same Δ converge to Δ.
    t.setOffsetMs(1, 1, 8.0f);
    t.fold(1, 1, -3.0f, 1.0f);
    EXPECT_EQ(t.offsetMs(1, 1), -3.0f);
    for (int i = 0; i < 200; ++i)
        t.fold(2, 2, 4.0f, 0.3f);
    EXPECT_NEAR(t.offsetMs(2, 2), 4.0f, 4.0 * 0.002);
}

TEST(LiwcTable, ClampsWhenValueIsHugeOrNotANumber) {
    LiwcTable t;
    t.setOffsetMs(3, 4, 1e9f);
    EXPECT_EQ(t.offsetMs(3, 4), 60000.0f);
    t.setOffsetMs(3, 4, -1e9f);
    EXPECT_EQ(t.offsetMs(3, 4), -60000.0f);
    t.setOffsetMs(3, 4, 70000.0f);  // beyond fp16's 65504
    EXPECT_EQ(t.offsetMs(3, 4), 60000.0f);
    t.setOffsetMs(3, 4, std::numeric_limits<float>::quiet_NaN());
    EXPECT_EQ(t.offsetMs(3, 4), 0.0f);
    for (float v :
         {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()}) {
        t.setOffsetMs(3, 4, v);
        EXPECT_TRUE(std::isfinite(t.offsetMs(3, 4)));
        EXPECT_LE(std::fabs(t.offsetMs(3, 4)), 60000.0f);
    }
    // A NaN or huge Δ folded in leaves a finite entry.
    t.setOffsetMs(3, 4, 1.0f);
    t.fold(3, 4, std::numeric_limits<float>::quiet_NaN(), 0.3f);
    EXPECT_TRUE(std::isfinite(t.offsetMs(3, 4)));
    t.fold(3, 4, 3e38f, 0.9f);
    EXPECT_TRUE(std::isfinite(t.offsetMs(3, 4)));
    EXPECT_LE(std::fabs(t.offsetMs(3, 4)), 60000.0f);
}

}  // namespace
}  // namespace qvr
