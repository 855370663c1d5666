// The server's throughput estimate from acknowledgements (core/throughput_estimator.h): bytes
// over the time the link was busy with them, an EMA restarted after an idle pause.
#include "qvr/core/throughput_estimator.h"

#include <gtest/gtest.h>

namespace qvr {
namespace {

TEST(ThroughputEstimator, BytesOverTheLinksBusyTime) {
    ThroughputEstimator est(0.5);
    // Frame 1: two streams of 1 MB sent at t = 0 and 1 ms; acks at 40 ms and 80 ms: the second
    // waited behind the first until 40 ms → 2 MB / 80 ms.
    est.onSend(1, 1'000'000, 0);
    est.onSend(1, 1'000'000, 1'000'000);
    est.onAck(1, 1'000'000, 40'000'000);
    EXPECT_EQ(est.samples(), 0u);  // one stream still unacknowledged
    est.onAck(1, 1'000'000, 80'000'000);
    ASSERT_EQ(est.samples(), 1u);
    EXPECT_DOUBLE_EQ(est.throughputBps(), 2e6 * 8 / 0.08);
    // Frame 2: 1 MB in 20 ms = 400 Mbit/s; bits and busy time each an EMA with α = 0.5.
    est.onSend(2, 1'000'000, 100'000'000);
    est.onAck(2, 1'000'000, 120'000'000);
    EXPECT_DOUBLE_EQ(*est.lastSampleBps(), 400e6);
    EXPECT_DOUBLE_EQ(est.throughputBps(), (0.5 * 16e6 + 0.5 * 8e6) / (0.5 * 0.08 + 0.5 * 0.02));
    est.onAck(99, 5'000'000, 130'000'000);  // unknown frame: ignored
    EXPECT_EQ(est.samples(), 2u);
}

// A frame acknowledged 0.1 ms after the one before (a trace's burst) reads 800 Mbit/s on a
// 2 Mbit/s link. Averaged by the time it took, it moves the estimate a few percent; an average
// of the frames' rates read 201 Mbit/s (the UMTS trace: one such frame, 580 Mbit/s, sent the
// estimate from 3 to 146 Mbit/s and LIWC's X to 0 for ten frames).
TEST(ThroughputEstimator, AFrameAcknowledgedInABurstCountsForTheTimeItTook) {
    ThroughputEstimator est(0.25);
    int64_t t = 0;
    for (uint32_t f = 1; f <= 10; ++f) {  // 10 KB in 40 ms: 2 Mbit/s
        est.onSend(f, 10'000, t);
        est.onAck(f, 10'000, t + 40'000'000);
        t += 50'000'000;
    }
    ASSERT_NEAR(est.throughputBps(), 2e6, 1.0);
    est.onSend(11, 10'000, t);
    est.onAck(11, 10'000, t + 100'000);
    EXPECT_NEAR(*est.lastSampleBps(), 800e6, 1.0);
    EXPECT_LT(est.throughputBps(), 2.7e6);
    EXPECT_GT(est.throughputBps(), 2e6);
}

// The server's render + encode between a frame's layers is not link time: four 10 KB streams
// sent 8 ms apart, each acknowledged 2 ms after its send, carried 40 KB in 8 ms, not in 26.
TEST(ThroughputEstimator, LeavesOutTheGapsBetweenAFramesSends) {
    ThroughputEstimator est(0.5);
    for (int64_t k = 0; k < 4; ++k)
        est.onSend(1, 10'000, k * 8'000'000);
    for (int64_t k = 0; k < 4; ++k)
        est.onAck(1, 10'000, k * 8'000'000 + 2'000'000);
    ASSERT_EQ(est.samples(), 1u);
    EXPECT_DOUBLE_EQ(est.throughputBps(), 40'000 * 8 / 0.008);
}

// A frame queued behind the previous one is busy on the link only from that one's last ack:
// frame 2, sent at 5 ms while frame 1 held the link until 30 ms and acknowledged at 40 ms,
// took 10 ms of the link (reading 5-40 ms would halve a saturated link's rate).
TEST(ThroughputEstimator, AFrameQueuedBehindAnotherIsBusyFromItsAck) {
    ThroughputEstimator est(1.0);
    est.onSend(1, 30'000, 0);
    est.onSend(2, 10'000, 5'000'000);
    est.onAck(1, 30'000, 30'000'000);
    EXPECT_DOUBLE_EQ(est.throughputBps(), 30'000 * 8 / 0.030);
    est.onAck(2, 10'000, 40'000'000);
    EXPECT_DOUBLE_EQ(est.throughputBps(), 10'000 * 8 / 0.010);
}

// After a pause without samples (the headset drew everything itself) the next frame's sample
// replaces the average instead of moving it by alpha: a link that read 0.1 Mbit/s in a trace's
// outage must not keep the headset away from it for a dozen frames.
TEST(ThroughputEstimator, ASampleAfterAnIdlePauseStartsAfresh) {
    ThroughputEstimator est(0.25, 64, 1'000'000'000);
    est.onSend(1, 1'250, 0);
    est.onAck(1, 1'250, 100'000'000);  // 0.1 Mbit/s
    est.onSend(2, 1'250, 500'000'000);
    est.onAck(2, 1'250, 501'000'000);  // 10 Mbit/s, within the second: averaged
    EXPECT_DOUBLE_EQ(est.throughputBps(), 10'000 / (0.75 * 0.1 + 0.25 * 0.001));
    est.onSend(3, 1'250, 2'000'000'000);  // 1.5 s after the last sample
    est.onAck(3, 1'250, 2'001'000'000);
    EXPECT_DOUBLE_EQ(est.throughputBps(), 10e6);
    EXPECT_EQ(est.samples(), 3u);
}

TEST(ThroughputEstimator, ForgetsFramesBeyondItsWindow) {
    ThroughputEstimator est(0.25, 4);
    for (uint32_t f = 0; f < 10; ++f) {
        est.onSend(f, 1000, f * 1'000'000);
    }
    est.onAck(0, 1000, 50'000'000);  // evicted long ago
    EXPECT_EQ(est.samples(), 0u);
    est.onAck(9, 1000, 10'000'000);
    EXPECT_EQ(est.samples(), 1u);
    EXPECT_DOUBLE_EQ(est.throughputBps(), 8000.0 / 1e-3);
}

}  // namespace
}  // namespace qvr
