// LIWC's runtime objective (LiwcConfig::frame_period_objective, docs/LIWC.md "The runtime's
// objective"): with frames in flight the display's period is max(T_local, T_remote), so LIWC
// picks the e1 that minimises it, learning T_local and the server's part of T_remote as linear
// fits. And its software-reactive twin (LiwcConfig::reactive), which decides with the rings of
// the newest observed frame instead of the current one.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "qvr/controller/liwc.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/workload/workload.h"

namespace qvr {
namespace {

constexpr double kRingDeg = 1.0;

WorkloadHeader header() {
    WorkloadHeader h;
    h.profile = defaultHmdProfile();
    h.ring_deg = kRingDeg;
    h.rings = 100;
    h.scales = {1, 2, 4, 8, 16, 32};
    return h;
}

// A frame whose first 60 rings hold `triangles_per_ring` triangles each (nothing beyond) and
// every ring 30 000 pixels.
WorkloadFrame frame(int64_t index, double triangles_per_ring) {
    WorkloadFrame f;
    f.index = index;
    f.head.orientation = quatFromEulerDeg({10, 0, 0});
    f.gaze = {0, 0};
    for (int k = 0; k < 100; ++k) {
        f.triangles_per_ring.push_back(k < 60 ? triangles_per_ring : 0.0);
        f.pixels_per_ring.push_back(30000.0);
    }
    f.bits_per_pixel = {0.6, 1.0, 1.6, 2.6, 4.2, 6.8};
    return f;
}

// A made-up machine: the headset's busy time, the server's render + encode, and a link. Layers
// are coded at 0.4·s^0.9 bits per pixel (both eyes' layers sent).
struct Truth {
    double local_fixed_ms = 1.0;
    double local_triangles_per_ms = 40'000.0;
    double local_pixels_per_ms = 150'000.0;
    // T_remote = server + bytes / throughput; server = fixed + periphery triangles / rate, or a
    // constant when remote_constant_ms > 0 (the whole T_remote then, whatever e1).
    double server_fixed_ms = 2.0;
    double server_triangles_per_ms = 50'000.0;
    double remote_constant_ms = 0.0;
    double throughput_bps = 200e6;
    double noise = 0.0;  // relative, uniform ±
    // A frame whose e1 differs from the previous measured one's carries this fraction more bits
    // (the encoders' new canvas: a key frame), and its link time grows with them.
    double move_extra_bits = 0.0;
    // A frame whose e1 moved takes the server this fraction longer (its new canvases' key
    // frames: qvr run measured 1.1-2.5x a held frame's encode).
    double move_extra_server = 0.0;
    // The session's first frame carries this fraction more bits (every encoder's opening key
    // frame), and its link time grows with them.
    double opening_extra_bits = 0.0;
    // Frame canvas_frame carries canvas_extra_bits more bits whatever its e1 (a canvas that
    // shrank: every stream's key frame), and says so in new_canvas_streams when canvas_flagged.
    int64_t canvas_frame = -1;
    double canvas_extra_bits = 0.0;
    bool canvas_flagged = true;
    // Each layer's content: its bits over the law's (an object in the outer layer around an
    // empty middle).
    double middle_content = 1.0;
    double outer_content = 1.0;
    // The server sends each layer as it is encoded: T_remote is the longer of the server and
    // the transmission (plus 1 ms), not their sum; the link's stage is still the transmission.
    bool overlapped = false;
    mutable double last_e1_deg = -1.0;

    static double bitsPerPixel(double s) { return 0.4 * std::pow(s, 0.9); }

    double localMs(const WorkloadFrame& f, double e1) const {
        return local_fixed_ms +
               sumWithinDeg(f.triangles_per_ring, kRingDeg, e1) / local_triangles_per_ms +
               sumWithinDeg(f.pixels_per_ring, kRingDeg, e1) / local_pixels_per_ms;
    }
    double transmissionMs(const LayerPlan& plan) const {
        const double bits = 2.0 * (plan.middle_pixels * bitsPerPixel(plan.s1) * middle_content +
                                   plan.outer_pixels * bitsPerPixel(plan.s2) * outer_content);
        return bits / throughput_bps * 1000.0;
    }
    double serverMs(const WorkloadFrame& f, const LayerPlan& plan) const {
        if (!plan.hasRemote())
            return 0.0;
        const double periphery = sumTotal(f.triangles_per_ring) -
                                 sumWithinDeg(f.triangles_per_ring, kRingDeg, plan.e1_deg);
        return server_fixed_ms + periphery / server_triangles_per_ms;
    }
    double remoteMs(const WorkloadFrame& f, const LayerPlan& plan) const {
        if (!plan.hasRemote())
            return 0.0;
        if (remote_constant_ms > 0.0)
            return remote_constant_ms;
        if (overlapped)
            return std::max(serverMs(f, plan), transmissionMs(plan)) + 1.0;
        return serverMs(f, plan) + transmissionMs(plan);
    }

    // What the headset measures of frame f run at d.e1_deg.
    FrameMeasurement measure(const LayerPlanner& planner, const WorkloadFrame& f, const Decision& d,
                             std::mt19937& rng) const {
        std::uniform_real_distribution<double> u(1.0 - noise, 1.0 + noise);
        const LayerPlan plan = planner.plan(f.gaze, d.e1_deg);
        FrameMeasurement m;
        m.index = f.index;
        m.e1_deg = d.e1_deg;
        m.t_local_ms = localMs(f, d.e1_deg) * u(rng);
        m.t_remote_ms = remoteMs(f, plan) * u(rng);
        m.triangles_local = sumWithinDeg(f.triangles_per_ring, kRingDeg, d.e1_deg);
        m.pixels_local = sumWithinDeg(f.pixels_per_ring, kRingDeg, d.e1_deg);
        m.middle_pixels = 2.0 * plan.middle_pixels;
        m.outer_pixels = 2.0 * plan.outer_pixels;
        m.s1 = plan.s1;
        m.s2 = plan.s2;
        m.middle_bytes = m.middle_pixels * bitsPerPixel(plan.s1) * middle_content / 8.0;
        m.outer_bytes = m.outer_pixels * bitsPerPixel(plan.s2) * outer_content / 8.0;
        const bool moved = last_e1_deg >= 0.0 && std::fabs(d.e1_deg - last_e1_deg) > 0.05;
        const bool opening = last_e1_deg < 0.0;
        last_e1_deg = d.e1_deg;
        const bool canvas = f.index == canvas_frame;
        const double extra = moved     ? move_extra_bits
                             : opening ? opening_extra_bits
                             : canvas  ? canvas_extra_bits
                                       : 0.0;
        if (canvas && canvas_flagged && plan.hasRemote())
            m.new_canvas_streams = 4;
        if (extra > 0.0 && plan.hasRemote()) {
            m.middle_bytes *= 1.0 + extra;
            m.outer_bytes *= 1.0 + extra;
            m.t_remote_ms += extra * transmissionMs(plan) * u(rng);
        }
        if (moved && move_extra_server > 0.0 && plan.hasRemote())
            m.t_remote_ms += move_extra_server * serverMs(f, plan) * u(rng);
        m.throughput_bps = plan.hasRemote() ? throughput_bps : 0.0;
        return m;
    }
};

LiwcConfig periodConfig() {
    LiwcConfig c;
    c.frame_period_objective = true;
    return c;
}

// Runs `frames` frames of f through the policy, `depth` frames in flight (the runtime's
// pipeline: frame n + depth − 1 is decided before frame n is observed); returns the decisions.
std::vector<Decision> run(LiwcPolicy& liwc, const Truth& truth, const LayerPlanner& planner,
                          const WorkloadFrame& f, int frames, int depth, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<Decision> decided;
    std::vector<WorkloadFrame> shown;
    int observed = 0;
    for (int i = 0; i < frames; ++i) {
        WorkloadFrame fi = f;
        fi.index = i;
        decided.push_back(liwc.decide(fi));
        shown.push_back(fi);
        if (i + 1 - observed >= depth) {
            liwc.observe(truth.measure(planner, shown[static_cast<size_t>(observed)],
                                       decided[static_cast<size_t>(observed)], rng));
            ++observed;
        }
    }
    return decided;
}

// As run(), with the server's link estimate (truth's throughput) given before every decision, as
// the runtime's acks do, and `adjust` applied to each measurement (frame index at observation).
std::vector<Decision> runWithLink(LiwcPolicy& liwc, const Truth& truth, const LayerPlanner& planner,
                                  const WorkloadFrame& f, int frames, int depth, uint32_t seed,
                                  const std::function<void(FrameMeasurement&, int)>& adjust) {
    std::mt19937 rng(seed);
    std::vector<Decision> d;
    for (int i = 0; i < frames; ++i) {
        WorkloadFrame fi = f;
        fi.index = i;
        liwc.setLinkEstimate(truth.throughput_bps);
        d.push_back(liwc.decide(fi));
        const int observed = i + 1 - depth;
        if (observed < 0)
            continue;
        WorkloadFrame fo = f;
        fo.index = observed;
        FrameMeasurement m = truth.measure(planner, fo, d[size_t(observed)], rng);
        adjust(m, observed);
        liwc.observe(m);
    }
    return d;
}

// The runtime's first frames reach LIWC untimed (isStartUpFrame: t_local = t_remote = 0) though
// they held the initial e1. Ending the cold start on them left the headset's fit at its prior, a
// mobile GPU's rates: on a headset 5-10x slower and a slow link the fovea looked free, and e1
// walked to 25-30° before the fit caught up (qvr run --net rate:1: 250-390 ms frames for ten
// frames). The cold start ends on a held frame that was timed.
TEST(LiwcPeriodObjective, UntimedStartUpFramesDoNotEndTheColdStart) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.local_fixed_ms = 15.0;
    truth.local_triangles_per_ms = 8'000.0;
    truth.local_pixels_per_ms = 15'000.0;
    truth.throughput_bps = 6e6;
    truth.noise = 0.03;
    const WorkloadFrame f = frame(0, 20'000.0);
    auto periodAt = [&](double e1) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double remote = truth.remoteMs(f, plan);
        const double link = plan.hasRemote() ? truth.transmissionMs(plan) : 0.0;
        return std::max({truth.localMs(f, e1), remote - link, link, remote / 2.0});
    };
    double best = 1e18;
    for (double e = 1.0; e <= 60.0; e += 0.25)
        best = std::min(best, periodAt(e));
    ASSERT_GT(truth.localMs(f, 10.0), 40.0) << "a slow headset";
    LiwcPolicy liwc(h, periodConfig());
    constexpr int kStartUp = 4, kDepth = 2;
    const std::vector<Decision> d =
        runWithLink(liwc, truth, planner, f, 60, kDepth, 9, [](FrameMeasurement& m, int i) {
            if (i < kStartUp)
                m.t_local_ms = m.t_remote_ms = 0.0;
        });
    // Past the cold start (the initial 5° is the paper's start, not a decision), no frame more
    // than a third slower than the best e1's: without the rule e1 went to 20° (1.7x).
    double worst = 0.0;
    for (size_t i = kStartUp + kDepth; i < d.size(); ++i)
        worst = std::max(worst, periodAt(d[i].e1_deg) / best);
    EXPECT_LT(worst, 1.35);
    EXPECT_LT(periodAt(d.back().e1_deg), 1.1 * best);
}

// A link so slow that no periphery arrives within the wait: every frame's periphery is late, with
// no T_remote of its own. Those frames are timed all the same (the link is slower than the wait),
// so the cold start ends and LIWC leaves for the all-local cover.
TEST(LiwcPeriodObjective, LatePeripheriesEndTheColdStart) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.throughput_bps = 0.05e6;
    truth.noise = 0.03;
    const WorkloadFrame f = frame(0, 20'000.0);
    LiwcPolicy liwc(h, periodConfig());
    constexpr int kDepth = 2;
    const std::vector<Decision> d =
        runWithLink(liwc, truth, planner, f, 80, kDepth, 4, [](FrameMeasurement& m, int i) {
            if (i < kDepth) {  // the pipeline's fill: start-up, untimed
                m.t_local_ms = m.t_remote_ms = 0.0;
            } else if (m.middle_bytes + m.outer_bytes > 0.0) {
                m.periphery_late = true;
                m.t_remote_ms = 0.0;
            }
        });
    // All local from frame 30 on (e1 climbs one window step per measured frame, two frames
    // apart at this depth) but for a try of the link now and then, each after a longer wait
    // (the stale estimate's relaxation, TriesTheLinkAgainAfterAnOutage...), each refused.
    std::vector<size_t> tries;
    for (size_t i = 30; i < d.size(); ++i)
        if (planner.plan(f.gaze, d[i].e1_deg).hasRemote() &&
            !planner.plan(f.gaze, d[i - 1].e1_deg).hasRemote())
            tries.push_back(i);
    EXPECT_FALSE(planner.plan(f.gaze, d[30].e1_deg).hasRemote()) << d[30].e1_deg;
    EXPECT_LE(tries.size(), 2u);
    if (tries.size() == 2) {
        EXPECT_GT(tries[1] - tries[0], 35u);
    }
}

// On a link slower than the wait limit every periphery is late: what had come by the wait is a
// part of it, and the rest comes frames later. The bits law learns from the whole periphery when
// it arrives (observeLateArrival), not from the part, and not from a moved frame's (its new
// canvases' key frames). Before, the part was read as the frame's size or, when nothing had
// come, the 1 bit a pixel prior stayed (~17x what x264 sends): on the Verizon EVDO trace the
// link's time looked ~17x longer than it was and e1 fled to the all-local cover.
TEST(LiwcPeriodObjective, ALatePeripheryTeachesTheBitsLawWhenItArrives) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.throughput_bps = 1e6;
    const WorkloadFrame f = frame(0, 20'000.0);
    constexpr int kDepth = 2;
    LiwcPolicy liwc(h, periodConfig());
    const double prior = liwc.bitsPerPixelAt(1.0);
    std::vector<LateArrival> coming;
    runWithLink(liwc, truth, planner, f, 12, kDepth, 5, [&](FrameMeasurement& m, int i) {
        if (i < kDepth) {  // the start-up: untimed, nothing arrived
            m.t_local_ms = m.t_remote_ms = 0.0;
            m.middle_bytes = m.outer_bytes = 0.0;
            return;
        }
        coming.push_back({m.index, m.middle_bytes, m.outer_bytes, 0});
        m.periphery_late = true;
        m.middle_bytes *= 0.1;  // what had come by the wait limit
        m.outer_bytes = 0.0;
    });
    ASSERT_FALSE(coming.empty());
    EXPECT_DOUBLE_EQ(liwc.bitsPerPixelAt(1.0), prior) << "a part taught the law";
    // A frame's new canvas (a key frame, 8x) teaches nothing either.
    LateArrival key = coming.front();
    key.middle_bytes *= 8.0;
    key.outer_bytes *= 8.0;
    key.new_canvas_streams = 4;
    liwc.observeLateArrival(key);
    EXPECT_DOUBLE_EQ(liwc.bitsPerPixelAt(1.0), prior);
    for (const LateArrival& a : coming)
        liwc.observeLateArrival(a);
    EXPECT_NEAR(liwc.bitsPerPixelAt(1.0), Truth::bitsPerPixel(1.0), 0.01);
    EXPECT_NEAR(liwc.bitsPerPixelAt(8.0), Truth::bitsPerPixel(8.0),
                0.05 * Truth::bitsPerPixel(8.0));
}

// A frame the headset did not ask the server for (its window of outstanding requests was full,
// the link behind) says nothing of T_remote: it does not end the cold start, teach the table, or
// count as a frame that left the link idle (which relaxes the link's estimate toward the prior).
TEST(LiwcPeriodObjective, AWithheldPeripheryTeachesNothingOfTheRemoteSide) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.throughput_bps = 2e6;
    const WorkloadFrame f = frame(0, 20'000.0);
    constexpr int kDepth = 2;
    auto withheldFrom = [&](int first) {
        return [first](FrameMeasurement& m, int i) {
            if (i < kDepth) {
                m.t_local_ms = m.t_remote_ms = 0.0;
            } else if (i >= first) {
                m.periphery_withheld = true;
                m.t_remote_ms = 0.0;
                m.middle_bytes = m.outer_bytes = 0.0;
                m.throughput_bps = 0.0;
            }
        };
    };
    // Withheld from the start: the cold start holds the initial e1.
    LiwcPolicy cold(h, periodConfig());
    for (const Decision& d : runWithLink(cold, truth, planner, f, 40, kDepth, 3, withheldFrom(0)))
        EXPECT_DOUBLE_EQ(d.e1_deg, 5.0);
    // Withheld after a while: the table is not taught a T_remote of 0, nor does the link relax
    // toward the 200 Mbit/s prior (which would walk e1 down to the smallest fovea).
    LiwcPolicy warm(h, periodConfig());
    const std::vector<Decision> d =
        runWithLink(warm, truth, planner, f, 160, kDepth, 3, withheldFrom(40));
    const float offset =
        warm.table().offsetMs(warm.lastMotion(), LiwcTable::bucketOf(d.back().e1_deg));
    EXPECT_GT(offset, -2.0f) << "the table learnt a T_remote of 0";
    EXPECT_NEAR(d.back().e1_deg, d[40].e1_deg, 3.0);
}

// T_remote that does not fall with e1 (the server's fixed cost dominates): a larger fovea only
// lengthens the headset's busy time, so every e1 with T_local below T_remote gives the same
// period and the lower motion-to-photon latency wins — LIWC walks down to e1_min.
TEST(LiwcPeriodObjective, DriftsToTheSmallestFoveaWhenTRemoteDoesNotFallWithE1) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.remote_constant_ms = 40.0;
    truth.throughput_bps = 2e9;
    truth.noise = 0.05;
    const WorkloadFrame f = frame(0, 20'000.0);
    // T_local at 25° is ~17 ms: far below T_remote, so nothing but latency separates the e1.
    ASSERT_LT(truth.localMs(f, 25.0), 20.0);
    for (int depth : {1, 2}) {
        for (double start : {5.0, 25.0}) {
            LiwcConfig c = periodConfig();
            c.e1_initial_deg = start;
            LiwcPolicy liwc(h, c);
            const std::vector<Decision> d = run(liwc, truth, planner, f, 120, depth, 31);
            // At the bottom after a few tens of frames (the cold-start fits may first move it
            // either way).
            for (size_t i = 0; i < d.size(); ++i) {
                if (i >= 80) {
                    EXPECT_LE(d[i].e1_deg, c.e1_min_deg + 1.5)
                        << "depth " << depth << " start " << start << " frame " << i;
                }
                EXPECT_GE(d[i].e1_deg, c.e1_min_deg);
                EXPECT_TRUE(std::isfinite(d[i].t_local_pred_ms));
                EXPECT_TRUE(std::isfinite(d[i].t_remote_pred_ms));
            }
            // What it predicts for T_remote has learned the flat 40 ms (within the noise).
            EXPECT_NEAR(d.back().t_remote_pred_ms, 40.0, 4.0)
                << "depth " << depth << " start " << start;
        }
    }
}

// The same flat T_remote, but far above what the headset takes for the whole view (a link too
// slow for any periphery: every frame arrives at the wait limit). Each step of the ±5° window
// changes the period by nothing, so only a look past the window finds the all-local cover,
// where there is no T_remote at all; LIWC must walk there and stay.
TEST(LiwcPeriodObjective, LeavesAFlatPeriodForTheAllLocalCoverWhenTRemoteExceedsIt) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.remote_constant_ms = 500.0;
    truth.noise = 0.05;
    const WorkloadFrame f = frame(0, 20'000.0);
    // The whole view costs the headset ~51 ms: a tenth of T_remote.
    ASSERT_LT(truth.localMs(f, 100.0), 60.0);
    for (int depth : {1, 2}) {
        LiwcConfig c = periodConfig();
        LiwcPolicy liwc(h, c);
        const std::vector<Decision> d = run(liwc, truth, planner, f, 120, depth, 13);
        for (size_t i = 80; i < d.size(); ++i) {
            EXPECT_FALSE(planner.plan(f.gaze, d[i].e1_deg).hasRemote())
                << "depth " << depth << " frame " << i << " e1 " << d[i].e1_deg;
            EXPECT_EQ(d[i].t_remote_pred_ms, 0.0) << "depth " << depth << " frame " << i;
        }
    }
}

// The acks' estimate changes only when a frame's periphery is acknowledged. In an outage the
// periphery comes too late to be shown (so LIWC measures nothing of it) and its acks, when they
// come, read 0.04 Mbit/s: LIWC heads for the all-local cover, sends nothing, and the estimate
// stays where the outage left it although the link came back. An estimate that no frame has
// refreshed relaxes toward the prior; LIWC tries the link again and the fresh sample brings e1
// back to where it was before the outage. A late periphery is news of the link: in the outage
// LIWC tries the link only now and then.
TEST(LiwcPeriodObjective, TriesTheLinkAgainAfterAnOutageLeftItsEstimateLow) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.noise = 0.03;
    truth.throughput_bps = 20e6;
    const WorkloadFrame f = frame(0, 20'000.0);
    LiwcConfig c = periodConfig();
    c.e1_initial_deg = 10.0;
    LiwcPolicy liwc(h, c);
    std::mt19937 rng(5);
    double reported = truth.throughput_bps;  // what the server last reported
    std::vector<Decision> d;
    int first_cover = -1, back = -1;
    for (int i = 0; i < 400; ++i) {
        WorkloadFrame fi = f;
        fi.index = i;
        liwc.setLinkEstimate(reported);
        d.push_back(liwc.decide(fi));
        FrameMeasurement m = truth.measure(planner, fi, d.back(), rng);
        const bool sent = m.middle_bytes + m.outer_bytes > 0.0;
        if (sent && i >= 60 && i < 100) {  // the outage
            m.periphery_late = true;
            m.t_remote_ms = 0.0;
            m.middle_bytes = m.outer_bytes = 0.0;
            m.throughput_bps = 0.0;
            reported = 0.04e6;
        } else if (sent) {
            reported = truth.throughput_bps;
        }
        liwc.observe(m);
        if (!sent && first_cover < 0)
            first_cover = i;
        if (i >= 100 && first_cover >= 0 && back < 0 && sent)
            back = i;
    }
    const double before = d[59].e1_deg;
    ASSERT_TRUE(planner.plan(f.gaze, before).hasRemote()) << before;
    ASSERT_GE(first_cover, 60) << "the outage sent LIWC to the all-local cover";
    ASSERT_LT(first_cover, 100);
    ASSERT_GE(back, 100) << "LIWC never tried the link again";
    EXPECT_LT(back, 200);
    EXPECT_NEAR(d.back().e1_deg, before, 2.5);
}

// T_local rises and T_remote falls with e1. With `depth` frames in flight the headset, the server
// and the link each work on their own frame: the period is the slowest stage's and no shorter
// than the remote chain over the frames in flight, max(L, S, X, (S + X) / depth) — at depth 1
// max(T_local, T_remote), smallest where they cross. Its minimum is computed here from the
// made-up machine on a fine grid.
TEST(LiwcPeriodObjective, SettlesNearTheBestPipelinedPeriodWhenLocalRisesAndRemoteFalls) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.noise = 0.03;
    const WorkloadFrame f = frame(0, 20'000.0);
    auto periodAt = [&](double e1, int depth) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double local = truth.localMs(f, e1), remote = truth.remoteMs(f, plan);
        const double link = plan.hasRemote() ? truth.transmissionMs(plan) : 0.0;
        return std::max({local, remote - link, link, remote / depth});
    };
    double crossing = -1.0;
    for (double e = 2.0; e <= 50.0; e += 0.1)
        if (crossing < 0.0 && truth.localMs(f, e) >= truth.remoteMs(f, planner.plan(f.gaze, e)))
            crossing = e;
    // The made-up machine crosses well inside LIWC's range, with both sides moving there.
    ASSERT_GT(crossing, 12.0);
    ASSERT_LT(crossing, 40.0);
    ASSERT_GT(truth.remoteMs(f, planner.plan(f.gaze, 5.0)),
              1.2 * truth.remoteMs(f, planner.plan(f.gaze, crossing)));
    for (int depth : {1, 2}) {
        double best_e = 0.0, best_period = INFINITY;
        for (double e = 2.0; e <= 50.0; e += 0.1)
            if (periodAt(e, depth) < best_period) {
                best_period = periodAt(e, depth);
                best_e = e;
            }
        if (depth == 1) {
            ASSERT_NEAR(best_e, crossing, 0.2);
        }
        for (double start : {5.0, 45.0}) {
            LiwcConfig c = periodConfig();
            c.e1_initial_deg = start;
            c.frames_in_flight = depth;
            LiwcPolicy liwc(h, c);
            const std::vector<Decision> d = run(liwc, truth, planner, f, 150, depth, 7);
            for (size_t i = 100; i < d.size(); ++i) {
                // The period it runs at is within 5% of the best one, near where that lies.
                EXPECT_LE(periodAt(d[i].e1_deg, depth), 1.05 * best_period)
                    << "depth " << depth << " start " << start << " frame " << i;
                EXPECT_NEAR(d[i].e1_deg, best_e, 2.0)
                    << "depth " << depth << " start " << start << " frame " << i;
            }
        }
    }
}

// A headset under a CFS quota of 0.3 of its core (seed 11235 c10: 2CylinderEngine, a Verizon LTE
// trace, share 0.3): the fovea render and the periphery's decode run before the quota throttles,
// so their own times are their CPU, but the headset's busy time is its whole CPU over the share.
// The render's time alone gave L a slope a third of the busy time's; the period looked flat in e1
// while the busy time rose, the tie went to the smaller motion-to-photon of a larger fovea, and qvr
// ran at e1 8-10° (30-38 FPS) where fixed 4-6° ran at 43.
TEST(LiwcPeriodObjective, UnderACpuQuotaTheRendersSlopeIsItsCpuOverTheShare) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    constexpr double kShare = 0.3;
    Truth truth;
    truth.local_fixed_ms = 4.0;  // UCA, decode and the rest, in CPU ms
    truth.local_triangles_per_ms = 100'000.0;
    truth.local_pixels_per_ms = 1'500'000.0;
    truth.server_triangles_per_ms = 200'000.0;
    truth.throughput_bps = 20e6;
    truth.noise = 0.02;
    const WorkloadFrame f = frame(0, 20'000.0);
    auto renderCpu = [&](double e1) { return truth.localMs(f, e1) - truth.local_fixed_ms; };
    // The periphery's decode: 1 ms a million pixels, falling as the fovea grows.
    auto decodeCpu = [&](double e1) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        return plan.hasRemote() ? 2.0 * double(plan.middle_pixels + plan.outer_pixels) * 1e-6 : 0.0;
    };
    auto busy = [&](double e1) { return (truth.localMs(f, e1) + decodeCpu(e1)) / kShare; };
    auto periodAt = [&](double e1) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double remote = truth.remoteMs(f, plan);
        const double link = plan.hasRemote() ? truth.transmissionMs(plan) : 0.0;
        return std::max({busy(e1), remote - link, link, remote / 2.0});
    };
    double best_e = 0.0, best_period = INFINITY;
    for (double e = 1.0; e <= 40.0; e += 0.1)
        if (periodAt(e) < best_period) {
            best_period = periodAt(e);
            best_e = e;
        }
    // The made-up headset: the link binds at small e1, the quota past the best.
    ASSERT_GT(best_e, 4.0);
    ASSERT_LT(best_e, 25.0);
    ASSERT_GT(periodAt(best_e + 8.0), 1.15 * best_period);
    auto runAt = [&](double share) {
        LiwcConfig c = periodConfig();
        c.e1_initial_deg = 3.0;
        LiwcPolicy liwc(h, c);
        liwc.setHeadsetShare(share);
        return runWithLink(liwc, truth, planner, f, 150, 2, 11, [&](FrameMeasurement& m, int) {
            m.t_render_ms = renderCpu(m.e1_deg);
            m.t_decode_ms = decodeCpu(m.e1_deg);
            m.t_local_ms = busy(m.e1_deg);
        });
    };
    auto meanPeriod = [&](const std::vector<Decision>& d) {
        double sum = 0.0;
        for (size_t i = 100; i < d.size(); ++i)
            sum += periodAt(d[i].e1_deg);
        return sum / double(d.size() - 100);
    };
    const std::vector<Decision> told = runAt(kShare);
    for (size_t i = 100; i < told.size(); ++i)
        EXPECT_NEAR(told[i].e1_deg, best_e, 2.5) << "frame " << i;
    EXPECT_LE(meanPeriod(told), 1.03 * best_period);
    // Not told of the quota, the same LIWC sees a third of L's slope and runs past the best e1.
    const std::vector<Decision> untold = runAt(1.0);
    EXPECT_GT(meanPeriod(untold), 1.02 * meanPeriod(told));
    EXPECT_GT(untold.back().e1_deg, told.back().e1_deg);
}

// Two frames in flight on one timeline: the headset starts frame n once it has done frame n − 1
// and frame n − 2's layers have arrived; the server serves the requests in turn, and the link
// carries the frames in turn, so the server works on a frame while the link carries the one
// before. T_remote runs from the request or the previous frame's arrival, as the runtime's.
// Returns the decisions and the arrivals.
struct Timeline {
    std::vector<Decision> decided;
    std::vector<double> arrival_ms;
};

Timeline runOnTimeline(LiwcPolicy& liwc, const Truth& truth, const LayerPlanner& planner,
                       const WorkloadFrame& f, int frames, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(1.0 - truth.noise, 1.0 + truth.noise);
    Timeline t;
    std::vector<FrameMeasurement> measured;
    double headset = 0.0, server_free = 0.0, link_free = 0.0;
    for (int i = 0; i < frames; ++i) {
        WorkloadFrame fi = f;
        fi.index = i;
        if (i >= 2)
            headset = std::max(headset, t.arrival_ms[static_cast<size_t>(i - 2)]);
        t.decided.push_back(liwc.decide(fi));
        FrameMeasurement m = truth.measure(planner, fi, t.decided.back(), rng);
        const LayerPlan plan = planner.plan(fi.gaze, t.decided.back().e1_deg);
        const double previous = i > 0 ? t.arrival_ms.back() : 0.0;
        double arrival = headset;
        if (plan.hasRemote()) {
            server_free = std::max(headset, server_free) + truth.serverMs(fi, plan) * u(rng);
            link_free = std::max(server_free, link_free) + truth.transmissionMs(plan) * u(rng);
            arrival = link_free;
            m.request_ms = headset;
            m.arrival_ms = arrival;
            m.t_remote_ms = arrival - std::max(headset, previous);
        }
        t.arrival_ms.push_back(arrival);
        headset += m.t_local_ms;
        measured.push_back(m);
        if (i >= 1)
            liwc.observe(measured[static_cast<size_t>(i - 1)]);
    }
    return t;
}

// The server is the slowest stage and the link carries a frame in most of a server's frame time.
// T_remote is then the server's frame, the transmission hidden behind the next frame's render:
// read as server + transmission in turn, the server's fit took the link's time off and LIWC,
// seeing a cheap server, balanced the headset against the link at a smaller fovea (a 1 Mbit/s
// run: server 30 ms a frame, read as 7). It must settle where the headset meets the server.
TEST(LiwcPeriodObjective, LearnsTheServersFrameWhenItsRenderHidesTheTransmission) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    const WorkloadFrame f = frame(0, 20'000.0);
    Truth truth;
    truth.noise = 0.03;
    truth.server_triangles_per_ms = 40'000.0;
    auto stages = [&](double e1) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double server = truth.serverMs(f, plan), link = truth.transmissionMs(plan);
        return std::array<double, 3>{truth.localMs(f, e1), server, link};
    };
    auto periodAt = [&](double e1) {
        const auto [local, server, link] = stages(e1);
        return std::max({local, server, link, (server + link) / 2.0});
    };
    double best_e = 0.0, best_period = INFINITY;
    auto findBest = [&] {
        best_period = INFINITY;
        for (double e = 2.0; e <= 50.0; e += 0.1)
            if (periodAt(e) < best_period) {
                best_period = periodAt(e);
                best_e = e;
            }
    };
    findBest();
    // A link that takes three quarters of the server's time where the headset meets the server
    // (the transmission goes as 1 / throughput).
    truth.throughput_bps *= stages(best_e)[2] / (0.75 * stages(best_e)[1]);
    findBest();
    for (double start : {5.0, 40.0}) {
        LiwcConfig c = periodConfig();
        c.e1_initial_deg = start;
        c.frames_in_flight = 2;
        LiwcPolicy liwc(h, c);
        const Timeline t = runOnTimeline(liwc, truth, planner, f, 200, 5);
        const double period = (t.arrival_ms.back() - t.arrival_ms[149]) / 50.0;
        EXPECT_LE(period, 1.06 * best_period) << "start " << start;
        for (size_t i = 150; i < t.decided.size(); ++i)
            EXPECT_NEAR(t.decided[i].e1_deg, best_e, 2.0) << "start " << start << " frame " << i;
    }
}

// The reactive variant sees the current frame's rings only once that frame has been observed.
// A sudden jump of the fovea's triangles (a dense object comes into view) moves LIWC's decision
// on that very frame; the reactive one decides as before, and moves one frame later.
TEST(LiwcPeriodObjective, ReactiveDecidesWithTheRingsOfTheNewestObservedFrame) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    const Truth truth;  // noiseless, so both settle on a fixed point
    LiwcConfig c = periodConfig();
    c.e1_initial_deg = 20.0;
    LiwcPolicy qvr(h, c);
    c.reactive = true;
    LiwcPolicy sw(h, c);
    std::mt19937 rng(1);
    const WorkloadFrame steady = frame(0, 20'000.0);
    // The jump: the central 30 rings hold four times the triangles.
    WorkloadFrame dense = steady;
    for (int k = 0; k < 30; ++k)
        dense.triangles_per_ring[static_cast<size_t>(k)] *= 4.0;
    const int kJump = 120;
    for (int i = 0; i < kJump; ++i) {
        WorkloadFrame fi = steady;
        fi.index = i;
        const Decision a = qvr.decide(fi);
        const Decision b = sw.decide(fi);
        // The same frames, the same measurements: the same decisions.
        ASSERT_DOUBLE_EQ(a.e1_deg, b.e1_deg) << "frame " << i;
        qvr.observe(truth.measure(planner, fi, a, rng));
        sw.observe(truth.measure(planner, fi, b, rng));
    }
    // Frame kJump is dense. Twins of both policies see the steady frame instead.
    LiwcPolicy qvr_steady = qvr, sw_steady = sw;
    WorkloadFrame jump = dense, calm = steady;
    jump.index = calm.index = kJump;
    const Decision q = qvr.decide(jump), q_calm = qvr_steady.decide(calm);
    const Decision s = sw.decide(jump), s_calm = sw_steady.decide(calm);
    // LIWC shrinks the fovea on the dense frame itself.
    EXPECT_LE(q.e1_deg, q_calm.e1_deg - 1.0);
    EXPECT_GT(q.t_local_pred_ms, q_calm.t_local_pred_ms);
    // The reactive one decides the dense frame with the steady frame's rings: as if it were
    // steady.
    EXPECT_DOUBLE_EQ(s.e1_deg, s_calm.e1_deg);
    EXPECT_DOUBLE_EQ(s.t_local_pred_ms, s_calm.t_local_pred_ms);
    EXPECT_DOUBLE_EQ(s.t_remote_pred_ms, s_calm.t_remote_pred_ms);
    // Having observed the dense frame (at the e1 it chose), it moves on the next one; its twin,
    // which observed the steady frame at the same e1, does not.
    sw.observe(truth.measure(planner, jump, s, rng));
    sw_steady.observe(truth.measure(planner, calm, s_calm, rng));
    WorkloadFrame next_dense = dense, next_calm = steady;
    next_dense.index = next_calm.index = kJump + 1;
    const Decision s1 = sw.decide(next_dense), s1_calm = sw_steady.decide(next_calm);
    EXPECT_LE(s1.e1_deg, s1_calm.e1_deg - 1.0);
    EXPECT_GT(s1.t_local_pred_ms, s1_calm.t_local_pred_ms);
}

// The moves LIWC makes over frames `from`-299 of a run on `truth`, which `flip` changes before
// each frame (the best e1 moves with it).
template <typename Flip>
int movesOver(Truth truth, Flip flip, int from) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    LiwcPolicy liwc(h, periodConfig());
    std::mt19937 rng(5);
    int moves = 0;
    double last_e1 = -1.0;
    for (int i = 0; i < 300; ++i) {
        WorkloadFrame fi = frame(i, 20'000.0);
        flip(truth, i);
        const Decision d = liwc.decide(fi);
        if (i >= from && std::fabs(d.e1_deg - last_e1) > 0.05)
            ++moves;
        last_e1 = d.e1_deg;
        liwc.observe(truth.measure(planner, fi, d, rng));
    }
    return moves;
}

// The cost of moving e1 (docs/LIWC.md): on a link-bound machine a frame whose e1 moved carries
// a key frame's bits. The link's rate flips every 25 frames, which moves the best e1; LIWC
// measures the extra (κ) from the sizes it is sent and charges a move with it, spread over the
// frames an e1 holds, so it follows the flips far less often than on the same machine where a
// move is free.
TEST(LiwcPeriodObjective, MovesE1LessWhenAMoveCostsTheLinkAKeyFrame) {
    auto moves = [](double move_extra_bits) {
        Truth truth;
        truth.move_extra_bits = move_extra_bits;
        return movesOver(
            truth, [](Truth& t, int i) { t.throughput_bps = (i / 25) % 2 ? 60e6 : 15e6; }, 100);
    };
    // Free, e1 follows the link and the fits' noise 94 times; with the key frames charged it
    // moves under a tenth as often (65 times with κ left out).
    const int free_moves = moves(0.0), costly_moves = moves(4.0);
    ASSERT_GE(free_moves, 20);
    EXPECT_LE(costly_moves * 10, free_moves)
        << "free " << free_moves << ", costly " << costly_moves;
}

// The same on a server-bound machine: a moved frame's key frames cost the server's encoder time,
// not the link's bytes. The server's speed flips every 25 frames; LIWC measures the moved
// frames' server time over the held ones' and charges a move with it, so it follows the flips
// less often than where a move is free (without κ_S the costly run moves more, not less).
TEST(LiwcPeriodObjective, MovesE1LessWhenAMoveCostsTheServerTime) {
    auto moves = [](double move_extra_server) {
        Truth truth;
        truth.move_extra_server = move_extra_server;
        truth.noise = 0.02;
        return movesOver(
            truth,
            [](Truth& t, int i) { t.server_triangles_per_ms = (i / 25) % 2 ? 30'000.0 : 12'000.0; },
            100);
    };
    // Free, e1 follows the flips in 1° steps (35 moves); charged, in a few larger ones (14; 46
    // with κ_S left out).
    const int free_moves = moves(0.0), costly_moves = moves(1.0);
    ASSERT_GE(free_moves, 20);
    EXPECT_LE(costly_moves * 2, free_moves) << "free " << free_moves << ", costly " << costly_moves;
}

// The runtime's first timed frames can show the server nothing: their T_remote is what the
// transmission takes at the acks' first estimate (qvr run on the UMTS trace: server times of 0
// and 8 ms, then 90-140). The first move was then measured against a server fit that knew
// nothing: read as the move's cost (its frame 30x the fit's prediction), it priced every later
// move out and held e1 at 5° for 120 frames. A move's cost is its frame over the next frame that
// held the same e1, and a server time of 0 teaches nothing; e1 reaches the best period as it
// does without the blind start (without either rule: 1.15-1.3x the best period).
TEST(LiwcPeriodObjective, AMoveBeforeTheServerFitKnewAnythingDoesNotPriceOutLaterMoves) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.noise = 0.03;
    truth.move_extra_server = 0.5;  // a move's key frames: 1.5x a held frame's server time
    const WorkloadFrame f = frame(0, 20'000.0);
    auto periodAt = [&](double e1) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double link = plan.hasRemote() ? truth.transmissionMs(plan) : 0.0;
        const double remote = truth.remoteMs(f, plan);
        return std::max({truth.localMs(f, e1), remote - link, link, remote / 2.0});
    };
    double best_period = INFINITY;
    for (double e = 2.0; e <= 50.0; e += 0.1)
        best_period = std::min(best_period, periodAt(e));
    // The server is the slowest stage at 5° by far: e1 must move up to reach the best period.
    ASSERT_GT(periodAt(5.0), 1.3 * best_period);
    auto periodsOver = [&](int blind_frames, double sliver) {
        LiwcPolicy liwc(h, periodConfig());
        const std::vector<Decision> d = runWithLink(
            liwc, truth, planner, f, 150, 2, 11, [&](FrameMeasurement& m, int observed) {
                // The first frames' T_remote is their transmission and a sliver of the
                // server's time.
                const double link_ms =
                    (m.middle_bytes + m.outer_bytes) * 8.0 / truth.throughput_bps * 1000.0;
                if (observed >= 1 && observed <= blind_frames)
                    m.t_remote_ms = link_ms + sliver * (m.t_remote_ms - link_ms);
            });
        double worst = 0.0;
        for (size_t i = 100; i < d.size(); ++i)
            worst = std::max(worst, periodAt(d[i].e1_deg));
        return worst;
    };
    EXPECT_LE(periodsOver(0, 0.0), 1.05 * best_period);
    for (double sliver : {0.0, 0.05})
        EXPECT_LE(periodsOver(2, sliver), 1.05 * best_period) << "sliver " << sliver;
}

// A frame that held e1 but whose encoders opened new canvases (a canvas shrunk 30 frames after a
// move, four key frames at once): read as the steady state, its bytes doubled the predicted
// T_remote and moved e1 (sweep 31337 c13). Flagged by the server's headers, it is a move's late
// cost: e1 stays within a degree of a run without it; unflagged, it moves (so the test can tell).
TEST(LiwcPeriodObjective, AHeldFramesNewCanvasIsAMovesCostNotTheSteadyState) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    const WorkloadFrame f = frame(0, 20'000.0);
    auto decisions = [&](double extra_bits, bool flagged) {
        Truth truth;
        truth.throughput_bps = 20e6;  // the link matters: a frame's bits move the period
        truth.canvas_frame = 80;
        truth.canvas_extra_bits = extra_bits;
        truth.canvas_flagged = flagged;
        LiwcConfig c = periodConfig();
        c.frames_in_flight = 2;
        LiwcPolicy liwc(h, c);
        return run(liwc, truth, planner, f, 110, 2, 3);
    };
    const std::vector<Decision> plain = decisions(0.0, true);
    auto widestGapAfterTheNewCanvas = [&](const std::vector<Decision>& d) {
        double gap = 0.0;
        for (size_t i = 80; i < d.size(); ++i)
            gap = std::max(gap, std::fabs(d[i].e1_deg - plain[i].e1_deg));
        return gap;
    };
    const double flagged = widestGapAfterTheNewCanvas(decisions(5.0, true));
    const double unflagged = widestGapAfterTheNewCanvas(decisions(5.0, false));
    EXPECT_LE(flagged, 1.0) << "unflagged " << unflagged;
    EXPECT_GE(unflagged, 2.0) << "flagged " << flagged;
}

// The session's first frame opens every encoder: key frames several times a P-frame's size (a
// 1 Mbit/s sweep run: 20.6 KB, then ~2.5 KB a frame). Read as the steady state, its bits inflate
// the bits law and e1 runs wide for a dozen frames. LIWC keeps the opening frame apart, holds e1
// until a frame that held is observed, and lets that frame's bits replace the prior, so the run
// with an opening key frame decides as the run without.
TEST(LiwcPeriodObjective, TheSessionsOpeningKeyFramesDoNotTeachTheSteadyState) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    const WorkloadFrame f = frame(0, 20'000.0);
    auto decisions = [&](double opening_extra_bits) {
        Truth truth;
        truth.throughput_bps = 20e6;  // the link matters: a frame's bits move the period
        truth.opening_extra_bits = opening_extra_bits;
        truth.move_extra_bits = 1.0;
        LiwcConfig c = periodConfig();
        c.frames_in_flight = 2;
        LiwcPolicy liwc(h, c);
        return run(liwc, truth, planner, f, 60, 2, 3);
    };
    const std::vector<Decision> plain = decisions(0.0), opened = decisions(7.0);
    double widest_gap = 0.0;
    for (size_t i = 0; i < plain.size(); ++i)
        widest_gap = std::max(widest_gap, std::fabs(opened[i].e1_deg - plain[i].e1_deg));
    EXPECT_LE(widest_gap, 1.0);
}

// With frames in flight the headset's busy time is mostly what e1 does not move (UCA, decode,
// the frame's overheads) and the host's preemptions shake it by several ms. Fitted whole, its
// slope in e1 was that noise's or the prior's: L(15°) 21 ms predicted where the headset was busy
// 10 ms at any e1 (qvr run, 2CylinderEngine, rate:1.33), and e1 stayed at 5-6°. Given the fovea
// render's own time (FrameMeasurement::t_render_ms), L is the rest's mean plus the render's fit.
TEST(LiwcPeriodObjective, TheFoveaRenderAloneTeachesHowLMovesWithE1) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.local_fixed_ms = 9.0;  // UCA and the rest
    truth.local_triangles_per_ms = 400'000.0;
    truth.local_pixels_per_ms = 3'000'000.0;
    truth.throughput_bps = 20e6;
    truth.noise = 0.02;
    const WorkloadFrame f = frame(0, 20'000.0);
    constexpr double kHiccupMs = 24.0;  // every 6th frame: the host ran something else
    const double busy_mean = kHiccupMs / 6.0;
    auto predictedOverTrue = [&](bool render_apart, double e1) {
        LiwcPolicy liwc(h, periodConfig());
        runWithLink(liwc, truth, planner, f, 90, 2, 5, [&](FrameMeasurement& m, int i) {
            const double render = truth.localMs(f, m.e1_deg) - truth.local_fixed_ms;
            m.t_render_ms = render_apart ? render : 0.0;
            if (i % 6 == 5)
                m.t_local_ms += kHiccupMs;
        });
        return liwc.predictLocalMs(f, e1) / (truth.localMs(f, e1) + busy_mean);
    };
    double worst_apart = 0.0, worst_whole = 0.0;
    for (const double e1 : {5.0, 15.0, 25.0}) {
        const double apart = predictedOverTrue(true, e1);
        EXPECT_NEAR(apart, 1.0, 0.1) << e1 << "°";
        worst_apart = std::max(worst_apart, std::fabs(apart - 1.0));
        // The whole busy time alone says it less well: the same run fitted on it is off by more
        // (by 20-30% with one line over every e1; 3-9% read at each e1's frames).
        worst_whole = std::max(worst_whole, std::fabs(predictedOverTrue(false, e1) - 1.0));
    }
    EXPECT_GT(worst_whole, 2.0 * worst_apart);
}

// The layers hold different content: a glTF engine in the outer layer around an empty middle
// (qvr run, 2CylinderEngine: 38 bytes a middle stream, ~770 an outer one). The one law b·s^γ
// read it as γ, at its bound of 2, and put the outer layer's bits 2.7x under; each layer's ratio
// to the law carries its content.
TEST(LiwcPeriodObjective, EachLayersOwnContentEntersItsBits) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth;
    truth.local_triangles_per_ms = 10'000.0;  // a slow headset: the periphery stays remote
    truth.throughput_bps = 20e6;
    truth.middle_content = 0.05;
    truth.outer_content = 3.0;
    const WorkloadFrame f = frame(0, 20'000.0);
    LiwcPolicy liwc(h, periodConfig());
    const std::vector<Decision> d =
        runWithLink(liwc, truth, planner, f, 40, 2, 3, [](FrameMeasurement&, int) {});
    const double e1 = d.back().e1_deg;
    const double truth_ms = truth.transmissionMs(planner.plan(f.gaze, e1));
    ASSERT_GT(truth_ms, 1.0);
    EXPECT_NEAR(liwc.predictRemoteMs(f, e1) / truth_ms, 1.0, 0.05) << e1 << "°";
}

// A fast headset (~9 ms of UCA and the rest, a cheap fovea render), a server of ~8 ms that sends
// each layer as it is encoded, and a link that sets the pace at small e1.
Truth overlappedLinkBound() {
    Truth truth;
    truth.local_fixed_ms = 9.0;
    truth.local_triangles_per_ms = 200'000.0;
    truth.local_pixels_per_ms = 2'000'000.0;
    truth.server_fixed_ms = 6.0;
    truth.server_triangles_per_ms = 600'000.0;
    truth.throughput_bps = 30e6;
    truth.overlapped = true;
    return truth;
}

// A server that sends each layer as it is encoded: the remote chain (request to last packet) is
// shorter than S + X, and the table learns that overlap as a negative offset. Put on X, it made a
// link-bound frame's link look free (X 11.5 ms, offset -11 ms at 1.33 Mbit/s), and e1 balanced
// L against S alone. The link's stage is its transmission; the offset corrects the chain.
TEST(LiwcPeriodObjective, TheChainsOverlapDoesNotHideTheLinksStage) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth = overlappedLinkBound();
    truth.noise = 0.02;
    const WorkloadFrame f = frame(0, 20'000.0);
    auto periodAt = [&](double e1) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double link = plan.hasRemote() ? truth.transmissionMs(plan) : 0.0;
        return std::max(
            {truth.localMs(f, e1), truth.serverMs(f, plan), link, truth.remoteMs(f, plan) / 2.0});
    };
    double best = 1e18;
    for (double e = 1.0; e <= 60.0; e += 0.25)
        best = std::min(best, periodAt(e));
    LiwcPolicy liwc(h, periodConfig());
    const std::vector<Decision> d =
        runWithLink(liwc, truth, planner, f, 80, 2, 11, [&](FrameMeasurement& m, int) {
            m.t_render_ms = m.t_local_ms - 9.0;
            // the server says its time (FrameHeader v2)
            m.server_ms = truth.serverMs(f, planner.plan(f.gaze, m.e1_deg));
        });
    const double link_at_5 = truth.transmissionMs(planner.plan(f.gaze, 5.0));
    ASSERT_GT(link_at_5, 1.3 * best) << "the link sets the pace at 5°";
    EXPECT_LT(periodAt(d.back().e1_deg), 1.08 * best) << d.back().e1_deg << "°";
}

// The table's cells are per (motion, eccentricity bucket), and most are empty: a cell no frame has
// folded reads the remote chain's error over all cells, not 0. Read as 0, the learned error
// vanished whenever the head's motion code or e1's bucket changed, every candidate's prediction
// jumped by it at once, and e1 flipped 5° and back on consecutive frames (2CylinderEngine,
// rate:1.33: offsets of -2.5 ms and 0 in turn), each move a key frame.
TEST(LiwcPeriodObjective, ACellNoFrameFoldedReadsTheChainsErrorNotZero) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    const Truth truth = overlappedLinkBound();
    const WorkloadFrame f = frame(0, 20'000.0);
    LiwcPolicy liwc(h, periodConfig());
    const std::vector<Decision> d =
        runWithLink(liwc, truth, planner, f, 60, 1, 4, [&](FrameMeasurement& m, int) {
            m.server_ms = truth.serverMs(f, planner.plan(f.gaze, m.e1_deg));
        });
    const double e1 = d.back().e1_deg;
    const double chain = truth.remoteMs(f, planner.plan(f.gaze, e1));
    ASSERT_NEAR(d.back().t_remote_pred_ms / chain, 1.0, 0.1) << "learned where it held";
    // The head turns: a motion code no frame has had.
    WorkloadFrame turned = f;
    turned.index = 60;
    turned.head.orientation = quatFromEulerDeg({10, 25, 0});
    liwc.setLinkEstimate(truth.throughput_bps);
    const Decision next = liwc.decide(turned);
    ASSERT_NE(liwc.lastMotion(), 0) << "a new motion code";
    EXPECT_NEAR(next.t_remote_pred_ms / truth.remoteMs(f, planner.plan(f.gaze, next.e1_deg)), 1.0,
                0.15);
}

// Past some e1 the fovea takes in a dense model the ring counts do not show as cost (a glTF
// engine's overdraw: 1-2k triangles, 33-70 ms a render at 12-15° on a 0.3 share, under 1 ms at
// 10°). One line of L through both sides put 10° at twice what it measured, and e1 fled to 3.5°
// where 10° was best (qvr sweep --seed 80808 c09). What the window measured at a larger e1 caps
// L. (What it does not yet do: remember the cliff once its frames leave the window, so e1 tries
// past it again about once a window.)
TEST(LiwcPeriodObjective, ACliffInTheFoveaRenderDoesNotBendLBelowIt) {
    const WorkloadHeader h = header();
    const LayerPlanner planner(h.profile);
    Truth truth = overlappedLinkBound();
    truth.throughput_bps = 8e6;
    truth.noise = 0.02;
    constexpr double kCliffDeg = 12.0, kCliffMs = 60.0;
    const WorkloadFrame f = frame(0, 20'000.0);
    auto cliff = [&](double e1) { return e1 > kCliffDeg ? kCliffMs : 0.0; };
    auto periodAt = [&](double e1, bool with_cliff) {
        const LayerPlan plan = planner.plan(f.gaze, e1);
        const double link = plan.hasRemote() ? truth.transmissionMs(plan) : 0.0;
        const double local = truth.localMs(f, e1) + (with_cliff ? cliff(e1) : 0.0);
        return std::max({local, truth.serverMs(f, plan), link, truth.remoteMs(f, plan) / 2.0});
    };
    double best = 1e18, best_e1 = 0.0, free_e1 = 0.0, free_best = 1e18;
    for (double e = 1.0; e <= 60.0; e += 0.25) {
        if (periodAt(e, true) < best)
            best = periodAt(e, true), best_e1 = e;
        if (periodAt(e, false) < free_best)
            free_best = periodAt(e, false), free_e1 = e;
    }
    ASSERT_GT(free_e1, kCliffDeg) << "without the cliff e1 would go past it";
    ASSERT_LE(best_e1, kCliffDeg);
    LiwcPolicy liwc(h, periodConfig());
    const std::vector<Decision> d =
        runWithLink(liwc, truth, planner, f, 160, 2, 13, [&](FrameMeasurement& m, int) {
            m.t_render_ms = m.t_local_ms - truth.local_fixed_ms + cliff(m.e1_deg);
            m.t_local_ms += cliff(m.e1_deg);
            m.server_ms = truth.serverMs(f, planner.plan(f.gaze, m.e1_deg));
        });
    // No decision goes more than one window step past the cliff: with decisions in flight
    // unmeasured the far search walked 12° to 37° in five frames, and once the cliff's frames
    // left the window it walked there again every window.
    for (size_t i = 0; i < d.size(); ++i)
        ASSERT_LE(d[i].e1_deg, kCliffDeg + 5.0 + 1e-9) << "frame " << i;
    // L at the e1 it holds, below the cliff, is what the frames there measure: the line through
    // both sides put it at 3.2-3.5x.
    for (const double e1 : {d.back().e1_deg, 10.0}) {
        ASSERT_LE(e1, kCliffDeg);
        EXPECT_NEAR(liwc.predictLocalMs(f, e1) / truth.localMs(f, e1), 1.0, 0.2) << e1 << "°";
    }
}

}  // namespace
}  // namespace qvr
