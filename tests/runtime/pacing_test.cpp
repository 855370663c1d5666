// Scan-out without waiting for vsync (VsyncPacer::queueForScanout, a two-image swapchain): a
// composed frame takes the first free slot at or after it is ready, never a slot another frame
// has, and the headset only waits while the previous frame still holds the other image.
#include "qvr/runtime/pacing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace qvr::runtime {
namespace {

constexpr int64_t kStartNs = 1'000;
constexpr int64_t kPeriodNs = 10'000'000;  // 100 Hz

int64_t slot(int64_t k) {
    return kStartNs + k * kPeriodNs;
}

TEST(VsyncPacerQueue, ReturnsTheFirstSlotAtOrAfterReadyWithoutWaitingForIt) {
    FakeClock clock(kStartNs);
    VsyncPacer pacer(clock, 100.0);
    ASSERT_EQ(pacer.periodNs(), kPeriodNs);
    // Ready 3 ms in: slot 1 at 10 ms, and no sleep (slot 1 − one period = slot 0 has passed).
    clock.advanceNs(3'000'000);
    EXPECT_EQ(pacer.queueForScanout(clock.nowNs()), slot(1));
    EXPECT_EQ(clock.nowNs(), kStartNs + 3'000'000);
    EXPECT_EQ(pacer.lastScanoutNs(), slot(1));
    // The next frame ready at 14 ms: slot 2; the previous frame's image is free at slot 1,
    // already past, so again no sleep.
    clock.advanceNs(11'000'000);
    EXPECT_EQ(pacer.queueForScanout(clock.nowNs()), slot(2));
    EXPECT_EQ(clock.nowNs(), kStartNs + 14'000'000);
    // Ready exactly on a slot: that slot.
    clock.sleepUntilNs(slot(5));
    EXPECT_EQ(pacer.queueForScanout(clock.nowNs()), slot(5));
    EXPECT_EQ(clock.nowNs(), slot(5));
}

TEST(VsyncPacerQueue, NeverGivesTheSameSlotTwiceAndWaitsOnlyForTheOtherImage) {
    FakeClock clock(kStartNs);
    VsyncPacer pacer(clock, 100.0);
    clock.advanceNs(2'000'000);
    // Three frames composed back to back at 2 ms: slots 1, 2, 3. The second may start on the
    // other image at once; the third must wait until the first has been scanned out at slot 1.
    EXPECT_EQ(pacer.queueForScanout(clock.nowNs()), slot(1));
    EXPECT_EQ(clock.nowNs(), kStartNs + 2'000'000);
    EXPECT_EQ(pacer.queueForScanout(clock.nowNs()), slot(2));
    EXPECT_EQ(clock.nowNs(), slot(1));
    EXPECT_EQ(pacer.queueForScanout(clock.nowNs()), slot(3));
    EXPECT_EQ(clock.nowNs(), slot(2));
    // A frame ready long before its slot is free only sleeps to one period before it.
    EXPECT_EQ(pacer.queueForScanout(kStartNs), slot(4));
    EXPECT_EQ(clock.nowNs(), slot(3));
}

// On random ready times: slots strictly increase, each the first at or after its frame's ready
// time unless that one was taken, and the clock never runs past one period before the slot.
TEST(VsyncPacerQueue, KeepsItsPromisesOnRandomReadyTimes) {
    FakeClock clock(kStartNs);
    VsyncPacer pacer(clock, 100.0);
    std::mt19937 rng(2);
    std::uniform_int_distribution<int64_t> work(0, 25'000'000);
    int64_t previous = -1;
    int waited = 0, taken = 0;
    for (int i = 0; i < 2000; ++i) {
        clock.advanceNs(work(rng));
        const int64_t before = clock.nowNs();
        const int64_t ready = before;
        const int64_t s = pacer.queueForScanout(ready);
        const int64_t after = clock.nowNs();
        ASSERT_GT(s, previous) << "frame " << i;
        ASSERT_EQ((s - kStartNs) % kPeriodNs, 0) << "frame " << i;
        ASSERT_GE(s, ready) << "frame " << i;
        const int64_t first_at_or_after =
            kStartNs + (ready - kStartNs + kPeriodNs - 1) / kPeriodNs * kPeriodNs;
        ASSERT_EQ(s, std::max(first_at_or_after, previous + kPeriodNs)) << "frame " << i;
        ASSERT_EQ(after, std::max(before, s - kPeriodNs)) << "frame " << i;
        waited += after > before;
        taken += s > first_at_or_after;
        previous = s;
    }
    // Both the waiting and the taken-slot cases occurred.
    EXPECT_GT(waited, 50);
    EXPECT_GT(taken, 50);
}

}  // namespace
}  // namespace qvr::runtime
