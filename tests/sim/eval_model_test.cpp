// Closed-form checks of the pieces `qvr eval`'s reproduction rests on: the radio's power at the
// simulated rates, the per-sample link noise averaged over a frame's packets, the display
// path's DRAM traffic and the UCA's throughput reading, vsync pacing, the one fitted parameter
// and the per-bench noise seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "qvr/sim/benches.h"
#include "qvr/sim/display_path.h"
#include "qvr/sim/energy.h"
#include "qvr/sim/evaluation.h"
#include "qvr/sim/simulator.h"

namespace qvr {
namespace {

TEST(Energy, RadioPowerFollowsHuangUpToTheMeasuredRangeAndStaysThereAbove) {
    const RadioPower wifi{137.01, 132.86};
    // 10 Mbit/s is inside the range: α·10 + β.
    EXPECT_NEAR(radioPowerW(wifi, 10e6), (137.01 * 10 + 132.86) * 1e-3, 1e-12);
    // 137 Mbit/s is above it: the power at 20 Mbit/s, not the line's 18.9 W.
    EXPECT_NEAR(radioPowerW(wifi, 137e6), (137.01 * 20 + 132.86) * 1e-3, 1e-12);
    EXPECT_EQ(radioPowerW(wifi, 0.0), 0.0);
    // A 2 ms transfer at that power.
    EXPECT_NEAR(radioEnergyMj(wifi, 137e6, 2.0), 2.0 * (137.01 * 20 + 132.86) * 1e-3, 1e-12);
}

TEST(Energy, NoBuiltInRadioDrawsMoreThanThreeWattsWhileItReceives) {
    for (const std::string& name : networkNames()) {
        auto spec = networkSpecByName(name);
        ASSERT_TRUE(spec.ok());
        for (double rate : {1e6, 20e6, spec->nominal_bps, 10.0 * spec->nominal_bps})
            EXPECT_LE(radioPowerW(spec->radio, rate), 3.0) << name << " at " << rate;
    }
}

TEST(Energy, AFramesPartsAreGpuRadioAndOther) {
    FrameEnergy e;
    e.gpu_dynamic_mj = 1.0;
    e.gpu_static_mj = 0.25;
    e.radio_mj = 2.0;
    e.uca_mj = 0.125;
    e.liwc_mj = 0.0625;
    EXPECT_DOUBLE_EQ(e.gpuMj(), 1.25);
    EXPECT_DOUBLE_EQ(e.radioMj(), 2.0);
    EXPECT_DOUBLE_EQ(e.otherMj(), 0.1875);
    EXPECT_DOUBLE_EQ(e.total(), 3.4375);
}

TEST(LinkNoise, PerSampleNoiseAveragesOverAFramesPackets) {
    const double eta = calibratedLinkEfficiency();
    NoisyLink link("n", 200e6, eta, 20.0, RadioPower{}, 7);
    const double payload = 150'000.0;
    const double packets = std::ceil(payload / (eta * 1500.0));
    EXPECT_EQ(link.packetsOf(payload), packets);
    EXPECT_EQ(link.packetsOf(10.0), 1.0);
    EXPECT_NEAR(link.noiseSigmaOver(payload), 0.1 / std::sqrt(packets), 1e-12);
    // The spread of many transfers' goodput is σ/√packets around the mean.
    const int n = 20000;
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
        const double g = link.transfer(0.0, payload).goodput_bps / link.meanGoodputBps();
        sum += g;
        sum2 += g * g;
    }
    const double m = sum / n;
    const double sd = std::sqrt(sum2 / n - m * m);
    EXPECT_NEAR(m, 1.0, 0.001);
    EXPECT_NEAR(sd, 0.1 / std::sqrt(packets), 0.05 * 0.1 / std::sqrt(packets));
}

TEST(DisplayPath, DramTrafficAtTable2sBandwidth) {
    // 16 bytes/cycle × 8 channels × 500 MHz = 64 GB/s = 64e6 bytes/ms.
    EXPECT_DOUBLE_EQ(dramBytesPerMs(), 64e6);
    const double px = 2.0 * 1920 * 2160;
    // ATW: one texel read + one pixel written, 4 bytes each.
    EXPECT_DOUBLE_EQ(gpuPassDramBytes(px, 1.0), px * 8.0);
    EXPECT_NEAR(dramMs(gpuPassDramBytes(px, 1.0)), px * 8.0 / 64e6, 1e-12);
    EXPECT_DOUBLE_EQ(ucaDramBytes(0.6 * px, px), 1.6 * px * 4.0);
}

TEST(DisplayPath, EachFramesTrafficIsItsPassesOrItsUcaPass) {
    auto trace = makeSuiteBench("doom3-l", 20);
    ASSERT_TRUE(trace.ok());
    const double frame_px =
        2.0 * trace->header.profile.width_px * static_cast<double>(trace->header.profile.height_px);
    for (Design d : {Design::Local, Design::Dfr, Design::Qvr}) {
        NoisyLink link("quiet", 200e6, calibratedLinkEfficiency(),
                       std::numeric_limits<double>::infinity(), RadioPower{}, 1);
        SimConfig cfg;
        cfg.design = d;
        cfg.frames = 20;
        const RunResult run = simulate(*trace, cfg, link);
        for (const FrameRecord& r : run.frames) {
            const double expected = d == Design::Qvr ? ucaDramBytes(r.shaded_pixels, frame_px)
                                    : d == Design::Dfr
                                        ? gpuPassDramBytes(frame_px, 1.0) * 2.0  // C + ATW
                                        : gpuPassDramBytes(frame_px, 1.0);       // ATW
            EXPECT_NEAR(r.display_dram_bytes, expected, 1e-6) << traitsOf(d).name;
            EXPECT_NEAR(r.display_dram_ms, dramMs(expected), 1e-9);
        }
    }
}

TEST(DisplayPath, UcaReadsFiveHundredThirtyTwoCyclesAsEachUnitsOccupancyPerTile) {
    const UcaConfig uca = defaultHardware(500.0).uca;
    // A 1920×2160 eye is 60 × 68 tiles of 32×32; two eyes; one tile at a time per unit.
    const double tiles = 2.0 * 60 * 68;
    EXPECT_NEAR(uca.wallMs(tiles), tiles * 532.0 / (500.0 * 1e3) / 2.0, 1e-12);
    EXPECT_NEAR(uca.wallMs(tiles), 4.341, 0.001);
}

TEST(Vsync, PacedFramesStartOncePerRefreshAndShowOnAVsync) {
    auto trace = makeSuiteBench("doom3-l", 60);
    ASSERT_TRUE(trace.ok());
    NoisyLink link("quiet", 200e6, calibratedLinkEfficiency(),
                   std::numeric_limits<double>::infinity(), RadioPower{}, 1);
    SimConfig cfg;
    cfg.design = Design::Qvr;
    cfg.frames = 60;
    cfg.vsync_paced = true;
    const RunResult run = simulate(*trace, cfg, link);
    const double period = 1000.0 / trace->header.profile.refresh_hz;
    for (size_t i = 0; i < run.frames.size(); ++i) {
        const FrameRecord& r = run.frames[i];
        EXPECT_GE(r.display_ms, r.display_ready_ms);
        EXPECT_LT(r.display_ms - r.display_ready_ms, period + 1e-9);
        EXPECT_NEAR(std::remainder(r.display_ms, period), 0.0, 1e-6);
        if (i > 0) {
            EXPECT_GE(r.pose_ms - run.frames[i - 1].pose_ms, period - 1e-9);
        }
    }
    EXPECT_LE(run.summary.fps_pipeline, trace->header.profile.refresh_hz + 1e-6);
}

TEST(Fit, RecoversTheTargetOnAClosedFormReduction) {
    // reduction(m) = m / (m + 0.003): 41% at m = 0.41·0.003/0.59.
    int calls = 0;
    auto reduction = [&](double m) {
        ++calls;
        return m / (m + 0.003);
    };
    const double m = fitAcuitySlope(reduction, 0.41, 1e-4, 0.0275, 1e-4);
    EXPECT_NEAR(reduction(m), 0.41, 1e-4);
    EXPECT_NEAR(m, 0.41 * 0.003 / 0.59, 1e-5);
    EXPECT_LT(calls, 20);
    // A target outside the bracket gives the nearer end.
    EXPECT_EQ(fitAcuitySlope(reduction, 0.999, 1e-4, 0.0275, 1e-4), 0.0275);
}

TEST(Seeds, ALinksNoiseDependsOnTheBenchAndNetworkNamesOnly) {
    EXPECT_EQ(benchLinkSeed("oa-dm5-h", "wifi"), benchLinkSeed("oa-dm5-h", "wifi"));
    EXPECT_NE(benchLinkSeed("oa-dm5-h", "wifi"), benchLinkSeed("oa-dm5-l", "wifi"));
    EXPECT_NE(benchLinkSeed("oa-dm5-h", "wifi"), benchLinkSeed("oa-dm5-h", "lte"));
}

}  // namespace
}  // namespace qvr
