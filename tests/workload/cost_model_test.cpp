// The ground-truth cost model: local = setup + triangles/rate + pixels/rate over the fovea disc,
// remote = periphery bytes·8/throughput (Eq. 2's form), GPU rates proportional to the clock.
#include "qvr/workload/cost_model.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace qvr {
namespace {

// Ring k holds 1000·(k+1) triangles and 5000 pixels; bits follow 0.6·s^0.7.
struct HandMade {
    WorkloadHeader header;
    WorkloadFrame frame;
    HandMade() {
        header.profile = defaultHmdProfile();
        header.ring_deg = 1.0;
        header.rings = 100;
        header.scales = {1, 2, 4, 8, 16, 32};
        frame.gaze = {4.0, -2.0};
        for (int k = 0; k < header.rings; ++k) {
            frame.triangles_per_ring.push_back(1000.0 * (k + 1));
            frame.pixels_per_ring.push_back(5000.0);
        }
        for (double s : header.scales)
            frame.bits_per_pixel.push_back(0.6 * std::pow(s, 0.7));
    }
};

// Triangles within e of ring sums 1000·(k+1), by hand: whole rings plus the split one.
double trianglesWithin(double e) {
    const int whole = static_cast<int>(std::floor(e));
    double sum = 1000.0 * whole * (whole + 1) / 2.0;
    sum += 1000.0 * (whole + 1) * (e - whole);
    return sum;
}

TEST(CostModel, ChargesFoveaWorkToGpuWhenComputingLocalTime) {
    const HandMade w;
    GpuModel gpu;
    gpu.setup_ms = 0.4;
    gpu.triangles_per_ms_at_500 = 40'000.0;
    gpu.pixels_per_ms_at_500 = 200'000.0;
    const CostModel model(w.header, gpu, 100e6);
    for (double e1 : {1.0, 2.5, 5.0, 7.25, 13.0, 30.0}) {
        const FrameCost c = model.cost(w.frame, e1);
        const double tris = trianglesWithin(e1);
        const double pixels = 5000.0 * e1;
        EXPECT_NEAR(c.triangles_local, tris, 1e-6);
        EXPECT_NEAR(c.pixels_local, pixels, 1e-6);
        EXPECT_NEAR(c.local_ms, 0.4 + tris / 40'000.0 + pixels / 200'000.0, 1e-9) << e1;
    }
}

TEST(CostModel, DividesPeripheryBitsByThroughputWhenComputingRemoteTime) {
    const HandMade w;
    for (double bps : {50e6, 137.6e6, 344e6}) {
        const CostModel model(w.header, GpuModel{}, bps);
        EXPECT_DOUBLE_EQ(model.throughputBps(), bps);
        for (double e1 : {2.0, 5.0, 10.0, 20.0}) {
            const LayerPlan plan = model.planner().plan(w.frame.gaze, e1);
            const FrameCost c = model.cost(w.frame, plan);
            const double bits =
                2.0 * (static_cast<double>(plan.middle_pixels) * 0.6 * std::pow(plan.s1, 0.7) +
                       static_cast<double>(plan.outer_pixels) * 0.6 * std::pow(plan.s2, 0.7));
            EXPECT_NEAR(c.bytes.total(), bits / 8.0, 1e-6 * bits);
            EXPECT_NEAR(c.remote_ms, bits / bps * 1000.0, 1e-9 * c.remote_ms) << e1;
            EXPECT_DOUBLE_EQ(c.frameMs(), std::max(c.local_ms, c.remote_ms));
            // The e1 overload plans the same way.
            EXPECT_DOUBLE_EQ(model.cost(w.frame, e1).remote_ms, c.remote_ms);
        }
    }
}

TEST(CostModel, HalvesRemoteTimeWhenThroughputDoubles) {
    const HandMade w;
    CostModel model(w.header, GpuModel{}, 100e6);
    const double slow = model.cost(w.frame, 8.0).remote_ms;
    model.setThroughputBps(200e6);
    EXPECT_NEAR(model.cost(w.frame, 8.0).remote_ms, slow / 2.0, 1e-12 * slow);
}

TEST(GpuModel, ScalesRatesWithClockWhenFrequencyChanges) {
    GpuModel gpu;
    EXPECT_DOUBLE_EQ(gpu.trianglesPerMs(), gpu.triangles_per_ms_at_500);
    EXPECT_DOUBLE_EQ(gpu.pixelsPerMs(), gpu.pixels_per_ms_at_500);
    gpu.freq_mhz = 1000.0;
    EXPECT_DOUBLE_EQ(gpu.trianglesPerMs(), 2.0 * gpu.triangles_per_ms_at_500);
    EXPECT_DOUBLE_EQ(gpu.pixelsPerMs(), 2.0 * gpu.pixels_per_ms_at_500);
    gpu.freq_mhz = 125.0;
    EXPECT_DOUBLE_EQ(gpu.trianglesPerMs(), 0.25 * gpu.triangles_per_ms_at_500);

    const HandMade w;
    GpuModel base;
    GpuModel fast = base;
    fast.freq_mhz = 2.0 * base.freq_mhz;
    const CostModel slow_model(w.header, base, 100e6);
    const CostModel fast_model(w.header, fast, 100e6);
    for (double e1 : {3.0, 12.0}) {
        const double slow = slow_model.cost(w.frame, e1).local_ms - base.setup_ms;
        const double quick = fast_model.cost(w.frame, e1).local_ms - fast.setup_ms;
        EXPECT_NEAR(quick, slow / 2.0, 1e-9 * slow);
        // The clock does not touch the network.
        EXPECT_DOUBLE_EQ(fast_model.cost(w.frame, e1).remote_ms,
                         slow_model.cost(w.frame, e1).remote_ms);
    }
}

TEST(CostModel, RendersWholeFrameLocallyWhenFoveaCoversField) {
    const HandMade w;
    const CostModel model(w.header, GpuModel{}, 100e6);
    const double cover = model.planner().geometry().coverEccentricityDeg(w.frame.gaze);
    const FrameCost c = model.cost(w.frame, cover + 1.0);
    EXPECT_EQ(c.remote_ms, 0.0);
    EXPECT_EQ(c.bytes.total(), 0.0);
    EXPECT_DOUBLE_EQ(c.triangles_local, sumTotal(w.frame.triangles_per_ring));
    EXPECT_DOUBLE_EQ(c.pixels_local, sumTotal(w.frame.pixels_per_ring));
    EXPECT_DOUBLE_EQ(c.local_ms, model.localOnlyMs(w.frame));
    const GpuModel g;
    EXPECT_NEAR(model.localOnlyMs(w.frame),
                g.setup_ms + sumTotal(w.frame.triangles_per_ring) / g.trianglesPerMs() +
                    sumTotal(w.frame.pixels_per_ring) / g.pixelsPerMs(),
                1e-9);
}

TEST(CostModel, RaisesLocalTimeWhenE1Grows) {
    const HandMade w;
    const CostModel model(w.header, GpuModel{}, 100e6);
    double prev = 0.0;
    for (double e1 = 0.0; e1 < 90.0; e1 += 0.5) {
        const double local = model.cost(w.frame, e1).local_ms;
        EXPECT_GE(local, prev) << e1;
        prev = local;
    }
    // At e1 = 0 only the fixed cost is left.
    EXPECT_DOUBLE_EQ(model.cost(w.frame, 0.0).local_ms, GpuModel{}.setup_ms);
}

}  // namespace
}  // namespace qvr
