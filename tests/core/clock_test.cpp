// The clock seam: the fake moves only when told to or when someone sleeps on it; the steady
// clock moves forward and its sleep waits.
#include <gtest/gtest.h>

#include "qvr/core/clock.h"

namespace qvr {
namespace {

TEST(FakeClock, MovesOnlyWhenAdvancedSetOrSleptOn) {
    FakeClock clock(1'000);
    EXPECT_EQ(clock.nowNs(), 1'000);
    clock.advanceNs(500);
    EXPECT_EQ(clock.nowNs(), 1'500);
    clock.sleepUntilNs(10'000);
    EXPECT_EQ(clock.nowNs(), 10'000);
    clock.sleepUntilNs(2'000);  // a deadline already past: no move back
    EXPECT_EQ(clock.nowNs(), 10'000);
    clock.setNs(42);
    EXPECT_EQ(clock.nowNs(), 42);
}

TEST(SteadyClock, MovesForwardAndSleepsUntilTheDeadline) {
    Clock& clock = SteadyClock::instance();
    const int64_t t0 = clock.nowNs();
    clock.sleepUntilNs(t0 + 2'000'000);
    EXPECT_GE(clock.nowNs(), t0 + 2'000'000);
    EXPECT_EQ(&SteadyClock::instance(), &clock);
}

TEST(Stopwatch, CountsTheTimeSinceItStarted) {
    const Stopwatch watch;
    const int64_t t0 = SteadyClock::instance().nowNs();
    SteadyClock::instance().sleepUntilNs(t0 + 3'000'000);
    EXPECT_GE(watch.elapsedMs(), 3.0);
}

}  // namespace
}  // namespace qvr
