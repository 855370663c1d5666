#include "qvr/experiment/calibration_fit.h"

#include <array>
#include <cmath>

#include <gtest/gtest.h>

#include "qvr/net/protocol.h"

namespace qvr::experiment {
namespace {

// Samples of a part whose cost is exactly base + per_mpx · Mpx, whatever it draws.
std::vector<CostSample> linearSamples(double base, double per_mpx) {
    std::vector<CostSample> s;
    const std::array<double, 4> px = {1e5, 2e5, 4e5, 8e5}, tri = {1e3, 3e3, 2e3, 5e3};
    for (size_t i = 0; i < px.size(); ++i)
        s.push_back({base + per_mpx * px[i] * 1e-6, px[i], tri[i]});
    return s;
}

TEST(CalibrationFit, UpperMedian) {
    EXPECT_EQ(upperMedian({}), 0.0);
    EXPECT_EQ(upperMedian({3.0}), 3.0);
    EXPECT_EQ(upperMedian({4.0, 1.0}), 4.0);
    EXPECT_EQ(upperMedian({5.0, 1.0, 3.0}), 3.0);
}

TEST(CalibrationFit, MeanOf) {
    EXPECT_EQ(meanOf({}), 0.0);
    EXPECT_EQ(meanOf({1.0, 2.0, 6.0}), 3.0);
}

TEST(CalibrationFit, SummarisePartSpreadsAndKeepsEverySample) {
    std::vector<CostSample> s = {{3.0, 1e5, 1e3}, {1.0, 2e5, 2e3, true, 5e5}, {2.0, 3e5, 3e3}};
    const PartCost cost{2.0, 0.0, 0.0};
    const CalibratedPart p = summarisePart("uca", "one frame", s, cost);
    EXPECT_EQ(p.name, "uca");
    EXPECT_EQ(p.what, "one frame");
    EXPECT_EQ(p.samples, 3);
    EXPECT_EQ(p.median_ms, 2.0);
    EXPECT_EQ(p.min_ms, 1.0);
    EXPECT_EQ(p.max_ms, 3.0);
    EXPECT_DOUBLE_EQ(p.residual_rms_pct, costResidualRmsPct(s, cost));
    ASSERT_EQ(p.samples_ms_px_tri.size(), 3u);
    EXPECT_EQ(p.samples_ms_px_tri[1], (std::array<double, 3>{1.0, 2e5, 2e3}));
    EXPECT_EQ(p.samples_full_frame, (std::vector<int>{0, 1, 0}));
    EXPECT_EQ(p.samples_fragments, (std::vector<double>{-1.0, 5e5, -1.0}));
    const CalibratedPart none = summarisePart("decode", "x", {}, cost);
    EXPECT_EQ(none.samples, 0);
    EXPECT_EQ(none.median_ms, 0.0);
}

TEST(CalibrationFit, PaddingRatioIsTheSlopeThroughTheOrigin) {
    EXPECT_EQ(fitPaddingBitsRatio({}), 0.0);
    EXPECT_DOUBLE_EQ(fitPaddingBitsRatio({{0.5, 1.25}, {1.0, 1.5}}), 0.5);
    EXPECT_EQ(fitPaddingBitsRatio({{0.5, 0.5}}), 0.0);    // clamped at 0
    EXPECT_EQ(fitPaddingBitsRatio({{0.1, 20.0}}), 10.0);  // and at 10
}

TEST(CalibrationFit, BitsByFrameIsSpentOverTheLaw) {
    RuntimeCosts costs;
    costs.bits_per_px_at_1 = 0.5;  // scale 1: 0.5 bits a pixel, middle and outer alike
    std::array<std::vector<BitsSample>, 2> bits;
    // Frame 1: the middle spent 2× the law over two samples, the outer 0.5×; frame 2 only the
    // middle (the law alone); frame 3 nothing.
    bits[0] = {{1.0, 100.0, 100.0, 1}, {1.0, 100.0, 100.0, 1}, {1.0, 100.0, 80.0, 2}};
    bits[1] = {{1.0, 100.0, 25.0, 1}, {1.0, 100.0, 50.0, 7}};  // frame 7 is past the motion
    const std::vector<double> keys = {11.0, 12.0, 13.0, 14.0};
    fitBitsByFrame(bits, keys, costs);
    ASSERT_EQ(costs.bits_frame_key.size(), 2u);  // the law-only tail dropped
    EXPECT_EQ(costs.bits_frame_key, (std::vector<double>{0.0, 12.0}));
    EXPECT_DOUBLE_EQ(costs.bits_frame_middle[1], 2.0);
    EXPECT_DOUBLE_EQ(costs.bits_frame_outer[1], 0.5);
    EXPECT_EQ(costs.bits_frame_middle[0], 1.0);
    EXPECT_EQ(costs.bits_frame_outer[0], 1.0);
}

TEST(CalibrationFit, FitsEveryPartInOrder) {
    CalibrationSamples s;
    s.decision = {{0.3, 0, 0}, {0.3, 0, 0}, {0.3, 0, 0}};
    s.plan_ms = {0.2, 0.1, 0.3};
    s.fovea = linearSamples(1.0, 40.0);
    s.server_render = linearSamples(2.0, 60.0);
    s.encode = linearSamples(0.5, 12.0);
    s.decode = linearSamples(0.25, 4.0);
    s.uca = linearSamples(5.0, 1.5);
    s.video_copy_ms = {1.0, 3.0, 2.0, 9.0};
    for (int f = 0; f < 6; ++f)
        for (double scale : {2.0, 4.0}) {
            const double px = 1e4;
            s.bits[0].push_back({scale, px, px * 0.4 * std::pow(scale, 1.5), f});
            s.bits[1].push_back({scale, px, px * 0.2 * std::pow(scale, 1.5), f});
        }
    s.frame_content_key = {1, 2, 3, 4, 5, 6};
    s.padding = {{0.5, 1.25}};
    s.keyframe_ratio = {std::vector<double>{6.0, 8.0, 7.0}, std::vector<double>{4.0}};
    s.periodic_keyframe_ratio = {3.0, 5.0};
    s.full_frame_bits_per_px = {0.1, 0.2};
    Calibration cal;
    fitCalibration(s, cal);
    const RuntimeCosts& c = cal.costs;
    EXPECT_NEAR(c.decision.base_ms, 0.3, 1e-9);
    EXPECT_EQ(c.frame_overhead_ms, 0.2);
    EXPECT_EQ(c.scanout_record_ms, 3.0);
    EXPECT_NEAR(c.fovea.ms_per_mpx, 40.0, 1e-6);
    EXPECT_NEAR(c.server_render.base_ms, 2.0, 1e-6);
    EXPECT_NEAR(c.encode.ms_per_mpx, 12.0, 1e-6);
    EXPECT_NEAR(c.decode.base_ms, 0.25, 1e-6);
    EXPECT_NEAR(c.uca.ms_per_mpx, 1.5, 1e-6);
    EXPECT_NEAR(c.bits_per_px_at_1, 0.4, 1e-9);
    EXPECT_NEAR(c.bits_scale_exponent, 1.5, 1e-9);
    EXPECT_NEAR(c.bits_outer_per_px_at_1, 0.2, 1e-9);
    EXPECT_EQ(cal.bits_samples, 24);
    EXPECT_NEAR(cal.bits_mean_over_geometric[0], 1.0, 1e-9);
    EXPECT_EQ(c.bits_frame_key, (std::vector<double>{1, 2, 3, 4, 5, 6}));
    EXPECT_NEAR(c.bits_frame_middle[3], 1.0, 1e-9);
    EXPECT_DOUBLE_EQ(c.padding_bits_ratio, 0.5);
    EXPECT_EQ(cal.padding_samples, 1);
    EXPECT_EQ(c.keyframe_bits_ratio, 7.0);
    EXPECT_EQ(c.keyframe_outer_bits_ratio, 4.0);
    EXPECT_EQ(c.keyframe_periodic_bits_ratio, 5.0);
    EXPECT_NEAR(c.bits_full_frame_per_px, 0.15, 1e-12);
    EXPECT_EQ(cal.bits_full_frame_samples, 2);
    std::vector<std::string> names;
    for (const CalibratedPart& p : cal.parts)
        names.push_back(p.name);
    EXPECT_EQ(names, (std::vector<std::string>{"decision", "fovea/local", "server render", "encode",
                                               "decode", "uca"}));
    EXPECT_EQ(cal.parts[1].samples, 4);
}

TEST(CalibrationFit, CoRunIsTheGeometricMeanOfThePairs) {
    CoRunPairs pairs;
    pairs.alone_ms = {10.0, 10.0, 20.0};
    pairs.shared_ms = {20.0, 10.0, 40.0};  // ratios 2, 1, 2
    const Calibration::CoRun c = fitCoRun(pairs, "headset", 1, "server");
    EXPECT_NEAR(c.slowdown, std::cbrt(4.0), 1e-12);
    EXPECT_EQ(c.samples, 3);
    EXPECT_EQ(c.alone_ms, 10.0);
    EXPECT_EQ(c.shared_ms, 20.0);
    EXPECT_EQ(c.ratio_p10, 1.0);
    EXPECT_EQ(c.ratio_p90, 2.0);
    EXPECT_EQ(c.note.rfind("headset frames (e1 = 10 deg) 10.00 ms alone, 20.00 ms with core 1 "
                           "doing the server's (medians); slowdown x1.587",
                           0),
              0u)
        << c.note;
    // A faster frame beside the load is noise: the slowdown is at least 1.
    pairs.shared_ms = {5.0, 5.0, 10.0};
    EXPECT_EQ(fitCoRun(pairs, "server", 0, "headset").slowdown, 1.0);
    EXPECT_EQ(fitCoRun({}, "server", 0, "headset").samples, 0);
}

TEST(CalibrationFit, LinksAreNetsProfilesAndPackets) {
    Calibration cal;
    describeLinks(cal);
    EXPECT_EQ(cal.costs.packet_payload_bytes, double(net::kMediaChunkBytes));
    EXPECT_EQ(cal.costs.packet_overhead_bytes, double(net::kMediaHeaderBytes));
    ASSERT_TRUE(cal.links.is_object());
    EXPECT_FALSE(cal.links.empty());
    for (const auto& [name, link] : cal.links.items()) {
        EXPECT_TRUE(link.contains("rate_bps")) << name;
        EXPECT_TRUE(link.contains("delay_ms")) << name;
    }
}

}  // namespace
}  // namespace qvr::experiment
