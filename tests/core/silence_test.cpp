// SilenceDetector: when the headset calls its server silent (qvr/core/silence.h).
#include "qvr/core/silence.h"

#include <gtest/gtest.h>

namespace qvr {
namespace {

TEST(SilenceDetector, BeforeAnyStreamTheLimitAloneDecides) {
    SilenceDetector d;
    d.restart(1000.0);
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 250.0);
    EXPECT_FALSE(d.silent(1250.0, 250.0));
    EXPECT_TRUE(d.silent(1250.5, 250.0));
    // One stream gives no spacing yet.
    d.onStream(1100.0);
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 250.0);
    EXPECT_TRUE(d.silent(1351.0, 250.0));
}

TEST(SilenceDetector, AFastServerIsJudgedOnTheLimit) {
    SilenceDetector d;
    for (int k = 0; k < 20; ++k)
        d.onStream(40.0 * k);
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 250.0);
    EXPECT_FALSE(d.silent(760.0 + 250.0, 250.0));
    EXPECT_TRUE(d.silent(760.0 + 251.0, 250.0));
}

TEST(SilenceDetector, ASlowServerGetsTwiceItsMedianSpacing) {
    SilenceDetector d;
    // Streams 260 ms apart, one outlier gap of 900 ms: the median ignores it.
    double t = 0.0;
    for (int k = 0; k < 8; ++k) {
        t += k == 3 ? 900.0 : 260.0;
        d.onStream(t);
    }
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 520.0);
    EXPECT_FALSE(d.silent(t + 500.0, 250.0));
    EXPECT_TRUE(d.silent(t + 521.0, 250.0));
    // Only the last eight gaps count: after eight 40 ms gaps the limit decides again.
    for (int k = 0; k < 8; ++k) {
        t += 40.0;
        d.onStream(t);
    }
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 250.0);
}

TEST(SilenceDetector, ANewSessionForgetsTheOldSpacing) {
    SilenceDetector d;
    for (int k = 0; k < 8; ++k)
        d.onStream(400.0 * k);
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 800.0);
    d.restart(5000.0);
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 250.0);
    EXPECT_TRUE(d.silent(5251.0, 250.0));
}

TEST(SilenceDetector, AStreamOutOfClockOrderCountsAsNoGap) {
    // A clock step backwards must not make a negative spacing that shortens the threshold.
    SilenceDetector d;
    d.onStream(1000.0);
    d.onStream(900.0);
    EXPECT_DOUBLE_EQ(d.thresholdMs(250.0), 250.0);
}

}  // namespace
}  // namespace qvr
