// LIWC (paper §4.1, Eq. 2): the first decision, Eq. 2's predictor with the estimates it starts
// from, the choice among delta tags, the table update after each frame, and the refresh of the
// GPU-rate, throughput and bits-per-pixel estimates.
#include "qvr/controller/liwc.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "qvr/workload/synthetic.h"

namespace qvr {
namespace {

// A default-profile header and a frame whose ring k holds 2000·(k+1) triangles and 30000 pixels.
struct Fixture {
    WorkloadHeader header;
    WorkloadFrame frame;
    Fixture() {
        header.profile = defaultHmdProfile();
        header.ring_deg = 1.0;
        header.rings = 100;
        header.scales = {1, 2, 4, 8, 16, 32};
        frame.head.orientation = quatFromEulerDeg({10, 0, 0});
        frame.gaze = {0, 0};
        for (int k = 0; k < header.rings; ++k) {
            frame.triangles_per_ring.push_back(2000.0 * (k + 1));
            frame.pixels_per_ring.push_back(30000.0);
        }
        frame.bits_per_pixel = {0.6, 1.0, 1.6, 2.6, 4.2, 6.8};
    }
};

// What the headset would measure for a frame at e1 under a made-up truth.
FrameMeasurement measure(const WorkloadFrame& f, const Decision& d, int64_t index,
                         double t_local_ms, double t_remote_ms) {
    FrameMeasurement m;
    m.index = index;
    m.e1_deg = d.e1_deg;
    m.t_local_ms = t_local_ms;
    m.t_remote_ms = t_remote_ms;
    m.triangles_local = sumWithinDeg(f.triangles_per_ring, 1.0, d.e1_deg);
    m.pixels_local = sumWithinDeg(f.pixels_per_ring, 1.0, d.e1_deg);
    return m;
}

TEST(LiwcPolicy, StartsAtFiveDegreesWhenFirstDeciding) {
    const Fixture w;
    LiwcPolicy liwc(w.header);
    EXPECT_EQ(liwc.name(), "liwc");
    EXPECT_DOUBLE_EQ(liwc.decide(w.frame).e1_deg, 5.0);
    LiwcConfig c;
    c.e1_initial_deg = 12.0;
    LiwcPolicy other(w.header, c);
    EXPECT_DOUBLE_EQ(other.decide(w.frame).e1_deg, 12.0);
    // On the synthetic default too, whatever its first frame holds.
    const WorkloadTrace t = generateSyntheticWorkload([] {
        SyntheticSpec s = defaultSyntheticSpec();
        s.frames = 2;
        return s;
    }());
    LiwcPolicy on_trace(t.header);
    EXPECT_DOUBLE_EQ(on_trace.decide(t.frames[0]).e1_deg, 5.0);
}

TEST(LiwcPolicy, PredictsEq2WithInitialEstimatesWhenNothingMeasured) {
    const Fixture w;
    LiwcConfig c;
    LiwcPolicy liwc(w.header, c);
    EXPECT_DOUBLE_EQ(liwc.gpuTrianglesPerMs(), c.gpu_triangles_per_ms_initial);
    EXPECT_DOUBLE_EQ(liwc.gpuPixelsPerMs(), c.gpu_pixels_per_ms_initial);
    EXPECT_DOUBLE_EQ(liwc.throughputBps(), c.throughput_bps_initial);
    const LayerPlanner planner(w.header.profile);
    // At table knots (e1 a multiple of 0.5°, gaze at the centre) the size lookup is exact.
    for (double e1 : {2.0, 5.0, 7.5, 10.0, 20.0, 33.5}) {
        const double tris = sumWithinDeg(w.frame.triangles_per_ring, 1.0, e1);
        const double pixels = sumWithinDeg(w.frame.pixels_per_ring, 1.0, e1);
        const double local =
            tris / c.gpu_triangles_per_ms_initial + pixels / c.gpu_pixels_per_ms_initial;
        EXPECT_NEAR(liwc.predictLocalMs(w.frame, e1), local, 1e-9 * local) << e1;
        const LayerPlan plan = planner.plan(w.frame.gaze, e1);
        const double bpp1 = c.bits_per_pixel_initial * std::pow(plan.s1, 0.7);
        const double bpp2 = c.bits_per_pixel_initial * std::pow(plan.s2, 0.7);
        const double bits = 2.0 * (static_cast<double>(plan.middle_pixels) * bpp1 +
                                   static_cast<double>(plan.outer_pixels) * bpp2);
        EXPECT_NEAR(liwc.predictRemoteMs(w.frame, e1), bits / c.throughput_bps_initial * 1000.0,
                    1e-6 * bits / c.throughput_bps_initial * 1000.0)
            << e1;
    }
    // Nothing remote once the fovea covers the field.
    EXPECT_EQ(liwc.predictRemoteMs(w.frame, 89.0), 0.0);
}

TEST(LiwcPolicy, OffersDeltaTagsMinusFiveToFiveWhenDeciding) {
    const Fixture w;
    LiwcPolicy liwc(w.header);
    const Decision first = liwc.decide(w.frame);
    liwc.observe(measure(w.frame, first, 0, 5.0, 5.0));
    liwc.decide(w.frame);
    const auto& cands = liwc.lastCandidates();
    for (int i = 0; i < 11; ++i) {
        EXPECT_EQ(cands[static_cast<size_t>(i)].delta_deg, i - 5);
        // Clamped below at e1_min (1°).
        EXPECT_DOUBLE_EQ(cands[static_cast<size_t>(i)].e1_deg, std::max(1.0, 5.0 + (i - 5)));
        EXPECT_DOUBLE_EQ(cands[static_cast<size_t>(i)].imbalanceMs(),
                         cands[static_cast<size_t>(i)].t_remote_pred_ms -
                             cands[static_cast<size_t>(i)].t_local_pred_ms +
                             cands[static_cast<size_t>(i)].offset_ms);
    }
}

TEST(LiwcPolicy, FollowsTableOffsetWhenItDominatesImbalance) {
    // An offset of +1000 ms on every bucket of the current motion makes every tag look
    // remote-bound: the tag that cancels most of it is +5. −1000 ms gives −5.
    const Fixture w;
    for (float offset : {1000.0f, -1000.0f}) {
        LiwcConfig c;
        c.interpolate = false;
        LiwcPolicy liwc(w.header, c);
        Decision d = liwc.decide(w.frame);
        liwc.observe(measure(w.frame, d, 0, 5.0, 5.0));
        d = liwc.decide(w.frame);  // settle; the same frame again is motion code 0
        ASSERT_EQ(liwc.lastMotion(), 0);
        liwc.observe(measure(w.frame, d, 1, 5.0, 5.0));
        for (int b = 0; b < LiwcTable::kEccentricityBuckets; ++b)
            liwc.table().setOffsetMs(0, b, offset);
        const double before = d.e1_deg;
        const Decision next = liwc.decide(w.frame);
        EXPECT_NEAR(next.e1_deg, std::max(1.0, before + (offset > 0 ? 5.0 : -5.0)), 1e-9)
            << offset << " from " << before;
        EXPECT_NE(next.e1_deg, before);
    }
}

TEST(LiwcPolicy, PicksTagThatCancelsImbalanceWhenTableIsEmpty) {
    // With interpolation off and no offsets, the choice is the tag with the smallest
    // |T_remote − T_local| predicted by Eq. 2.
    const Fixture w;
    LiwcConfig c;
    c.interpolate = false;
    c.table_warmup_frames = 1000;  // keep the table empty
    LiwcPolicy liwc(w.header, c);
    Decision d = liwc.decide(w.frame);
    for (int i = 1; i < 8; ++i) {
        liwc.observe(measure(w.frame, d, i - 1, 4.0, 6.0));
        d = liwc.decide(w.frame);
        double best = INFINITY;
        double best_e = -1;
        for (const LiwcCandidate& cand : liwc.lastCandidates()) {
            EXPECT_EQ(cand.offset_ms, 0.0);
            const double imb = std::fabs(cand.t_remote_pred_ms - cand.t_local_pred_ms);
            if (imb < best) {
                best = imb;
                best_e = cand.e1_deg;
            }
        }
        EXPECT_DOUBLE_EQ(d.e1_deg, best_e);
    }
}

TEST(LiwcPolicy, LeavesTableUntouchedWhenWarmingUp) {
    const Fixture w;
    LiwcPolicy liwc(w.header);
    Decision d = liwc.decide(w.frame);
    for (int i = 0; i < 3; ++i) {
        liwc.observe(measure(w.frame, d, i, 3.0, 9.0));
        for (int m = 0; m < kMotionCodes; m += 1)
            for (int b = 0; b < LiwcTable::kEccentricityBuckets; ++b)
                ASSERT_EQ(liwc.table().offsetMs(static_cast<uint16_t>(m), b), 0.0f);
        d = liwc.decide(w.frame);
    }
}

// The update rule (§4.1, docs/LIWC.md): after the warm-up frames, observe() folds
// Δ = (measured T_remote − T_local) − (the imbalance Eq. 2 predicted for the chosen e1) into the
// entry for (the frame's motion code, the chosen e1's bucket) as (1 − α)·old + α·Δ.
TEST(LiwcPolicy, FoldsMeasuredMinusPredictedImbalanceWhenObserving) {
    const Fixture w;
    LiwcConfig c;
    c.alpha = 0.3f;
    LiwcPolicy liwc(w.header, c);
    // A head that turns a little every frame, so the motion code varies.
    WorkloadFrame f = w.frame;
    Decision d = liwc.decide(f);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int folds = 0;
    for (int i = 0; i < 40; ++i) {
        const uint16_t motion = liwc.lastMotion();
        const int bucket = LiwcTable::bucketOf(d.e1_deg);
        const double old = liwc.table().offsetMs(motion, bucket);
        const double predicted = d.t_remote_pred_ms - d.t_local_pred_ms;
        const double t_local = 2.0 + 6.0 * u(rng);
        const double t_remote = 2.0 + 6.0 * u(rng);
        liwc.observe(measure(f, d, i, t_local, t_remote));
        const double now = liwc.table().offsetMs(motion, bucket);
        if (i < c.table_warmup_frames) {
            EXPECT_EQ(now, old) << "frame " << i;
        } else {
            const double delta = (t_remote - t_local) - predicted;
            const double expect = (1.0 - c.alpha) * old + c.alpha * delta;
            // fp16: half a unit in the last place of the result, at most 2^-11 relative.
            EXPECT_NEAR(now, expect, std::fabs(expect) * std::ldexp(1.0, -11) + 1e-4)
                << "frame " << i << " old " << old << " delta " << delta;
            ++folds;
        }
        f.head.orientation = quatFromEulerDeg({10.0 + 0.5 * (i % 3), 0.3 * (i % 2), 0});
        f.gaze = {(i % 4 == 0) ? 1.0 : 0.0, 0.0};
        d = liwc.decide(f);
    }
    EXPECT_GT(folds, 30);
}

TEST(LiwcPolicy, LearnsGpuRatesWhenMeasurementsFollowALinearModel) {
    // True local time: 0.5 ms + triangles / 35 000 + pixels / 90 000, at many e1.
    const Fixture w;
    LiwcPolicy liwc(w.header);
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> e(2.0, 25.0);
    for (int i = 0; i < 200; ++i) {
        Decision d;
        d.e1_deg = e(rng);
        FrameMeasurement m = measure(w.frame, d, i, 0.0, 0.0);
        m.pixels_local *= 0.5 + (i % 5) * 0.25;  // decorrelate pixels from triangles
        m.t_local_ms = 0.5 + m.triangles_local / 35'000.0 + m.pixels_local / 90'000.0;
        liwc.observe(m);
    }
    EXPECT_NEAR(liwc.gpuTrianglesPerMs(), 35'000.0, 0.02 * 35'000.0);
    EXPECT_NEAR(liwc.gpuPixelsPerMs(), 90'000.0, 0.02 * 90'000.0);
    const double tris = sumWithinDeg(w.frame.triangles_per_ring, 1.0, 10.0);
    const double pixels = sumWithinDeg(w.frame.pixels_per_ring, 1.0, 10.0);
    const double truth = 0.5 + tris / 35'000.0 + pixels / 90'000.0;
    EXPECT_NEAR(liwc.predictLocalMs(w.frame, 10.0), truth, 0.01 * truth);
}

TEST(LiwcPolicy, TracksThroughputAndBitsWhenAcknowledgementsArrive) {
    const Fixture w;
    LiwcPolicy liwc(w.header);
    for (int i = 0; i < 40; ++i) {
        FrameMeasurement m;
        m.index = i;
        m.e1_deg = 10.0;
        m.t_local_ms = 0.0;  // no local measurement: only the remote estimates move
        m.throughput_bps = 55e6;
        // Layers coded at 0.4·s^0.9 bits per pixel.
        m.s1 = 1.3;
        m.s2 = 9.0;
        m.middle_pixels = 4e5;
        m.outer_pixels = 1e5;
        m.middle_bytes = m.middle_pixels * 0.4 * std::pow(m.s1, 0.9) / 8.0;
        m.outer_bytes = m.outer_pixels * 0.4 * std::pow(m.s2, 0.9) / 8.0;
        liwc.observe(m);
    }
    EXPECT_NEAR(liwc.throughputBps(), 55e6, 1e-3 * 55e6);
    for (double s : {1.0, 2.0, 5.0, 12.0})
        EXPECT_NEAR(liwc.bitsPerPixelAt(s), 0.4 * std::pow(s, 0.9), 1e-3 * std::pow(s, 0.9)) << s;
    // The GPU estimates were left alone.
    EXPECT_DOUBLE_EQ(liwc.gpuTrianglesPerMs(), LiwcConfig{}.gpu_triangles_per_ms_initial);
}

TEST(LiwcPolicy, KeepsE1WithinLimitsWhenPushedHard) {
    const Fixture w;
    LiwcConfig c;
    LiwcPolicy liwc(w.header, c);
    Decision d = liwc.decide(w.frame);
    // Remote far slower than local for many frames: e1 climbs but never past the cover/max.
    for (int i = 0; i < 60; ++i) {
        liwc.observe(measure(w.frame, d, i, 0.1, 500.0));
        d = liwc.decide(w.frame);
        EXPECT_GE(d.e1_deg, c.e1_min_deg);
        EXPECT_LE(d.e1_deg, c.e1_max_deg);
        EXPECT_TRUE(std::isfinite(d.t_local_pred_ms));
        EXPECT_TRUE(std::isfinite(d.t_remote_pred_ms));
    }
    LiwcPolicy down(w.header, c);
    d = down.decide(w.frame);
    for (int i = 0; i < 60; ++i) {
        down.observe(measure(w.frame, d, i, 500.0, 0.1));
        d = down.decide(w.frame);
        EXPECT_GE(d.e1_deg, c.e1_min_deg);
    }
    EXPECT_LT(d.e1_deg, 5.0);
}

// A pipelined headset decides frame n+1 before it observes frame n. Each observation must fold
// into the entry of its own decision — (that frame's motion code, its e1's bucket) — not into the
// newest one's.
TEST(LiwcPolicy, FoldsEachObservationIntoItsOwnDecisionWhenObservationsLagAFrame) {
    const Fixture w;
    LiwcConfig c;
    c.interpolate = false;
    c.table_warmup_frames = 0;  // fold from the first observation
    c.alpha = 0.3f;
    LiwcPolicy liwc(w.header, c);
    // Frame 0 has no predecessor: motion code 0 at the initial 5° (bucket 1).
    const WorkloadFrame f0 = w.frame;
    const Decision d0 = liwc.decide(f0);
    ASSERT_EQ(liwc.lastMotion(), 0);
    const uint16_t m0 = 0;
    const int b0 = LiwcTable::bucketOf(d0.e1_deg);
    // Frame 1 turns the head: another motion code, whose offsets push e1 up by the +5 tag into
    // another bucket.
    WorkloadFrame f1 = w.frame;
    f1.head.orientation = quatFromEulerDeg({14, 2, 0});
    const uint16_t m1 = encodeMotion(f0.head, f1.head, f0.gaze, f1.gaze, c.motion);
    ASSERT_NE(m1, m0);
    for (int b = 0; b < LiwcTable::kEccentricityBuckets; ++b)
        liwc.table().setOffsetMs(m1, b, 1000.0f);
    const Decision d1 = liwc.decide(f1);
    ASSERT_EQ(liwc.lastMotion(), m1);
    ASSERT_DOUBLE_EQ(d1.e1_deg, d0.e1_deg + 5.0);
    const int b1 = LiwcTable::bucketOf(d1.e1_deg);
    ASSERT_NE(b1, b0);

    auto fp16Near = [](double expect) { return std::fabs(expect) * std::ldexp(1.0, -10) + 1e-3; };
    // Frame 0's measurement: its delta lands in (m0, b0); frame 1's cell keeps its 1000 ms.
    liwc.observe(measure(f0, d0, 0, 3.0, 9.0));
    const double delta0 = (9.0 - 3.0) - (d0.t_remote_pred_ms - d0.t_local_pred_ms);
    EXPECT_NEAR(liwc.table().offsetMs(m0, b0), c.alpha * delta0, fp16Near(c.alpha * delta0));
    EXPECT_EQ(liwc.table().offsetMs(m1, b1), 1000.0f);
    EXPECT_EQ(liwc.table().offsetMs(m1, b0), 1000.0f);
    EXPECT_EQ(liwc.table().offsetMs(m0, b1), 0.0f);
    // Frame 1's measurement: into (m1, b1), and frame 0's cell is left as it was.
    const float cell0 = liwc.table().offsetMs(m0, b0);
    liwc.observe(measure(f1, d1, 1, 7.0, 2.0));
    const double delta1 = (2.0 - 7.0) - (d1.t_remote_pred_ms - d1.t_local_pred_ms);
    const double expect1 = (1.0 - c.alpha) * 1000.0 + c.alpha * delta1;
    EXPECT_NEAR(liwc.table().offsetMs(m1, b1), expect1, fp16Near(expect1));
    EXPECT_EQ(liwc.table().offsetMs(m0, b0), cell0);
    EXPECT_EQ(liwc.table().offsetMs(m1, b0), 1000.0f);
}

// With one decision in flight, the next candidates step from the newest decision: an observation
// of an older frame must not pull e1 back to what that frame used.
TEST(LiwcPolicy, StepsFromTheNewestDecisionWhenObservationsLagAFrame) {
    const Fixture w;
    LiwcConfig c;
    c.interpolate = false;
    c.table_warmup_frames = 1000;  // keep the offsets as set
    LiwcPolicy liwc(w.header, c);
    // The same frame every time: motion code 0, whose offsets make every tag remote-bound.
    for (int b = 0; b < LiwcTable::kEccentricityBuckets; ++b)
        liwc.table().setOffsetMs(0, b, 1000.0f);
    std::vector<Decision> decided;
    decided.push_back(liwc.decide(w.frame));  // 5°, the initial e1
    decided.push_back(liwc.decide(w.frame));  // 10°
    for (int i = 0; i < 5; ++i) {
        // Observe frame i (its e1 lags the newest decision by one +5 tag), then decide i + 2.
        const Decision& seen = decided[static_cast<size_t>(i)];
        liwc.observe(measure(w.frame, seen, i, 5.0, 5.0));
        decided.push_back(liwc.decide(w.frame));
    }
    ASSERT_EQ(decided.size(), 7u);
    for (size_t k = 0; k < decided.size(); ++k)
        EXPECT_DOUBLE_EQ(decided[k].e1_deg, 5.0 + 5.0 * double(k)) << "decision " << k;
    // Once nothing later is open, the measured e1 is where the next step starts.
    liwc.observe(measure(w.frame, decided[5], 5, 5.0, 5.0));
    Decision last = decided.back();
    last.e1_deg = 12.0;  // the headset ran frame 6 at another e1 than decided
    liwc.observe(measure(w.frame, last, 6, 5.0, 5.0));
    EXPECT_DOUBLE_EQ(liwc.decide(w.frame).e1_deg, 17.0);
}

// learn_remote_base: the part of the measured T_remote beyond Eq. 2's transmission of the bytes
// actually sent, as a running mean with weight rate_ema, added to every remote prediction.
TEST(LiwcPolicy, AddsTheLearnedRemoteBaseOnlyWhenConfigured) {
    const Fixture w;
    // 250 000 bytes at the initial 200 Mbit/s take 10 ms to send; the server took 60 ms in all.
    auto measurement = [](int64_t i, double t_remote_ms) {
        FrameMeasurement m;
        m.index = i;
        m.e1_deg = 10.0;
        m.t_local_ms = 0.0;        // leave the GPU estimates alone
        m.throughput_bps = 0.0;    // and the throughput
        m.middle_bytes = 250'000;  // no pixel counts: the bits-per-pixel fit is left alone too
        m.t_remote_ms = t_remote_ms;
        return m;
    };
    for (bool learn : {false, true}) {
        LiwcConfig c;
        c.learn_remote_base = learn;
        LiwcPolicy liwc(w.header, c);
        const double before = liwc.predictRemoteMs(w.frame, 10.0);
        ASSERT_GT(before, 0.0);
        int n = 0;
        for (; n < 12; ++n) {
            liwc.decide(w.frame);
            liwc.observe(measurement(n, 60.0));
        }
        const double after = liwc.predictRemoteMs(w.frame, 10.0);
        if (!learn) {
            EXPECT_DOUBLE_EQ(after, before);
            continue;
        }
        // The running mean of 50 ms after 12 halvings of its distance to it.
        const double base = 50.0 * (1.0 - std::pow(1.0 - c.rate_ema, n));
        EXPECT_NEAR(after - before, base, 1e-9 * base);
        // The same base rides on every candidate, including one that sends more.
        EXPECT_NEAR(liwc.predictRemoteMs(w.frame, 3.0) - (after - before),
                    LiwcPolicy(w.header).predictRemoteMs(w.frame, 3.0), 1e-9);
        // A T_remote below the transmission time teaches a base of 0, never a negative one.
        for (int k = 0; k < 60; ++k)
            liwc.observe(measurement(n + k, 4.0));
        EXPECT_NEAR(liwc.predictRemoteMs(w.frame, 10.0), before, 1e-9 * before);
        EXPECT_GE(liwc.predictRemoteMs(w.frame, 10.0), before);
    }
}

// A caller that decides without observing keeps at most a few open decisions (liwc.h's
// kMaxPendingDecisions, 8): later observations fold into the newest ones, and once they are used
// up the next observation folds nothing and sets the e1 the next step starts from.
TEST(LiwcPolicy, KeepsABoundedQueueWhenDecidingWithoutObserving) {
    constexpr int kMaxPending = 8;
    const Fixture w;
    LiwcConfig c;
    c.interpolate = false;
    c.table_warmup_frames = 0;
    LiwcPolicy liwc(w.header, c);
    Decision d;
    for (int i = 0; i < 100; ++i) {
        d = liwc.decide(w.frame);
        ASSERT_GE(d.e1_deg, c.e1_min_deg);
        ASSERT_LE(d.e1_deg, c.e1_max_deg);
    }
    auto snapshot = [&liwc] {
        std::vector<float> v;
        for (int b = 0; b < LiwcTable::kEccentricityBuckets; ++b)
            v.push_back(liwc.table().offsetMs(0, b));
        return v;
    };
    int folds = 0;
    for (int i = 0; i < 20; ++i) {
        const std::vector<float> before = snapshot();
        Decision ran = d;
        ran.e1_deg = 20.0;
        liwc.observe(measure(w.frame, ran, i, 1.0, 90.0));
        if (snapshot() == before)
            break;
        ++folds;
    }
    EXPECT_EQ(folds, kMaxPending);
    // The observation that folded nothing set e1: the candidates are centred on 20°.
    liwc.decide(w.frame);
    EXPECT_DOUBLE_EQ(liwc.lastCandidates()[5].e1_deg, 20.0);
    for (const float v : snapshot())
        EXPECT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace qvr
