#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "qvr/experiment/calibration.h"
#include "qvr/sim/hardware.h"

namespace qvr::experiment {
namespace {

// A calibration with every output field away from its default.
Calibration sampleCalibration() {
    Calibration cal;
    cal.machine = "2 × Test CPU";
    cal.date = "a date";
    cal.command = "qvr calibrate --out x.toml";
    cal.seconds = 95.0;
    cal.load_avg_before = 0.5;
    RuntimeCosts& c = cal.costs;
    c.decision = {0.25, 0.0, 0.0};
    c.fovea = {1.5, 40.0, 0.03};
    c.fovea.full_frame_scale = 1.25;
    c.fovea.ms_per_mfrag = 2.5;
    c.fovea.frag_per_px = 1.75;
    c.server_render = {};
    c.server_render.power_coef_ms = 3.5;
    c.server_render.px_exponent = 0.75;
    c.server_render.tri_exponent = 0.125;
    c.server_render.full_frame_scale = 1.5;
    c.encode = {0.5, 11.0, 0.0};
    c.encode.full_frame_scale = 0.75;
    c.decode = {0.375, 3.5, 0.0};
    c.uca = {4.5, 1.25, 0.0};
    c.frame_overhead_ms = 0.0625;
    c.scanout_record_ms = 1.125;
    c.bits_per_px_at_1 = 0.0125;
    c.bits_scale_exponent = 1.5;
    c.bits_outer_per_px_at_1 = 0.0075;
    c.bits_outer_scale_exponent = 1.25;
    c.bits_full_frame_per_px = 0.125;
    c.keyframe_bits_ratio = 6.5;
    c.keyframe_outer_bits_ratio = 5.5;
    c.keyframe_periodic_bits_ratio = 3.75;
    c.padding_bits_ratio = 0.375;
    c.corun_headset_slowdown = 1.125;
    c.corun_server_slowdown = 1.25;
    c.bits_frame_key = {0.0, 1234567.0, 89.0};
    c.bits_frame_middle = {1.0, 1.125, 0.875};
    c.bits_frame_outer = {1.0, 0.75, 1.5};
    c.speed_reference_headset_ms = 30.5;
    c.speed_reference_server_ms = 60.25;
    c.speed_reference_key = "0123456789abcdef";
    CalibratedPart part;
    part.name = "fovea/local";
    part.what = "one eye's fovea";
    part.samples = 2;
    part.cost = c.fovea;
    part.median_ms = 4.0;
    part.samples_ms_px_tri = {{3.0, 1e5, 2e3}, {5.0, 2e5, 3e3}};
    part.samples_full_frame = {0, 1};
    part.samples_fragments = {-1.0, 4e5};
    cal.parts.push_back(part);
    cal.corun_headset.slowdown = 1.125;
    cal.corun_headset.note = "headset note";
    cal.corun_server.note = "server note";
    cal.speed_probes = {{30.0, 60.0}, {31.0, 60.5}};
    return cal;
}

TEST(CalibrationOutput, TomlRoundTripsThroughTheHardwareParser) {
    const Calibration cal = sampleCalibration();
    auto hw = parseHardwareConfig(cal.toToml(), "calibration", 500.0);
    ASSERT_TRUE(hw) << hw.error();
    EXPECT_TRUE(hw->runtime_pipeline);
    const RuntimeCosts& in = cal.costs;
    const RuntimeCosts& out = hw->runtime;
    EXPECT_DOUBLE_EQ(out.decision.base_ms, in.decision.base_ms);
    EXPECT_DOUBLE_EQ(out.fovea.base_ms, in.fovea.base_ms);
    EXPECT_DOUBLE_EQ(out.fovea.ms_per_mpx, in.fovea.ms_per_mpx);
    EXPECT_DOUBLE_EQ(out.fovea.ms_per_ktri, in.fovea.ms_per_ktri);
    EXPECT_DOUBLE_EQ(out.fovea.full_frame_scale, in.fovea.full_frame_scale);
    EXPECT_DOUBLE_EQ(out.fovea.ms_per_mfrag, in.fovea.ms_per_mfrag);
    EXPECT_DOUBLE_EQ(out.fovea.frag_per_px, in.fovea.frag_per_px);
    EXPECT_DOUBLE_EQ(out.server_render.power_coef_ms, in.server_render.power_coef_ms);
    EXPECT_DOUBLE_EQ(out.server_render.px_exponent, in.server_render.px_exponent);
    EXPECT_DOUBLE_EQ(out.server_render.tri_exponent, in.server_render.tri_exponent);
    EXPECT_DOUBLE_EQ(out.server_render.full_frame_scale, in.server_render.full_frame_scale);
    EXPECT_DOUBLE_EQ(out.encode.ms_per_mpx, in.encode.ms_per_mpx);
    EXPECT_DOUBLE_EQ(out.encode.full_frame_scale, in.encode.full_frame_scale);
    EXPECT_DOUBLE_EQ(out.decode.base_ms, in.decode.base_ms);
    EXPECT_DOUBLE_EQ(out.uca.ms_per_mpx, in.uca.ms_per_mpx);
    EXPECT_DOUBLE_EQ(out.frame_overhead_ms, in.frame_overhead_ms);
    EXPECT_DOUBLE_EQ(out.scanout_record_ms, in.scanout_record_ms);
    EXPECT_DOUBLE_EQ(out.bits_per_px_at_1, in.bits_per_px_at_1);
    EXPECT_DOUBLE_EQ(out.bits_outer_scale_exponent, in.bits_outer_scale_exponent);
    EXPECT_DOUBLE_EQ(out.bits_full_frame_per_px, in.bits_full_frame_per_px);
    EXPECT_DOUBLE_EQ(out.keyframe_bits_ratio, in.keyframe_bits_ratio);
    EXPECT_DOUBLE_EQ(out.keyframe_outer_bits_ratio, in.keyframe_outer_bits_ratio);
    EXPECT_DOUBLE_EQ(out.keyframe_periodic_bits_ratio, in.keyframe_periodic_bits_ratio);
    EXPECT_DOUBLE_EQ(out.padding_bits_ratio, in.padding_bits_ratio);
    EXPECT_DOUBLE_EQ(out.corun_headset_slowdown, in.corun_headset_slowdown);
    EXPECT_DOUBLE_EQ(out.corun_server_slowdown, in.corun_server_slowdown);
    EXPECT_EQ(out.bits_frame_key, in.bits_frame_key);
    EXPECT_EQ(out.bits_frame_middle, in.bits_frame_middle);
    EXPECT_EQ(out.bits_frame_outer, in.bits_frame_outer);
    EXPECT_DOUBLE_EQ(out.speed_reference_headset_ms, in.speed_reference_headset_ms);
    EXPECT_DOUBLE_EQ(out.speed_reference_server_ms, in.speed_reference_server_ms);
    EXPECT_EQ(out.speed_reference_key, in.speed_reference_key);
}

TEST(CalibrationOutput, TomlCommentsSummariseTheMeasurement) {
    const std::string toml = sampleCalibration().toToml();
    EXPECT_EQ(toml.rfind("# qvr calibrate: this machine's runtime costs", 0), 0u) << toml;
    EXPECT_NE(toml.find("# qvr calibrate --out x.toml\n"), std::string::npos);
    EXPECT_NE(toml.find("# machine: 2 × Test CPU\n"), std::string::npos);
    EXPECT_NE(toml.find("# fovea/local"), std::string::npos);
    EXPECT_NE(toml.find("# co-running, headset: headset note\n"), std::string::npos);
    EXPECT_NE(toml.find("# co-running, server: server note\n"), std::string::npos);
    EXPECT_NE(toml.find("the mean of 2): 30.00/60.00, 31.00/60.50 ms"), std::string::npos) << toml;
    // Every line before [runtime] is a comment.
    const std::string head = toml.substr(0, toml.find("[runtime]"));
    std::istringstream lines(head);
    for (std::string line; std::getline(lines, line);)
        EXPECT_EQ(line.rfind("# ", 0), 0u) << line;
}

TEST(CalibrationOutput, JsonHoldsEveryKey) {
    const nlohmann::json j = sampleCalibration().toJson();
    for (const char* key : {"machine",
                            "date",
                            "command",
                            "seconds",
                            "load_avg_before",
                            "parts",
                            "links",
                            "frame_overhead_ms",
                            "scanout_record_ms",
                            "bits_per_px_at_1",
                            "bits_scale_exponent",
                            "bits_outer_per_px_at_1",
                            "bits_outer_scale_exponent",
                            "bits_samples",
                            "bits_mean_over_geometric",
                            "bits_full_frame_per_px",
                            "bits_full_frame_samples",
                            "bits_frame",
                            "keyframe_bits_ratio",
                            "keyframe_outer_bits_ratio",
                            "padding_bits_ratio",
                            "keyframe_periodic_bits_ratio",
                            "padding_samples",
                            "codec_by_e1",
                            "packet_payload_bytes",
                            "packet_overhead_bytes",
                            "corun_headset",
                            "corun_server",
                            "speed_reference"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_EQ(j.size(), 29u);
    const nlohmann::json& part = j["parts"][0];
    EXPECT_EQ(part["name"], "fovea/local");
    EXPECT_EQ(part["law"], "linear");
    EXPECT_DOUBLE_EQ(part["full_frame_scale"].get<double>(), 1.25);
    EXPECT_EQ(part["samples_full_frame"], nlohmann::json::array({0, 1}));
    EXPECT_EQ(part.size(), 20u);
    EXPECT_DOUBLE_EQ(j["corun_headset"]["slowdown"].get<double>(), 1.125);
    EXPECT_EQ(j["corun_server"]["note"], "server note");
    EXPECT_EQ(j["speed_reference"]["probes"].size(), 2u);
    EXPECT_DOUBLE_EQ(j["speed_reference"]["probes"][1]["server_frame_ms"].get<double>(), 60.5);
    EXPECT_EQ(j["speed_reference"]["key"], "0123456789abcdef");
    EXPECT_EQ(j["bits_frame"]["content_key"][1], 1234567.0);
}

TEST(CalibrationOutput, CostLawTextNamesTheLaw) {
    PartCost linear{0.5, 12.0, 0.25};
    EXPECT_EQ(costLawText(linear), "0.500 + 12.000·Mpx + 0.2500·ktri");
    linear.ms_per_mfrag = 2.0;
    linear.frag_per_px = 1.5;
    linear.full_frame_scale = 1.2;
    EXPECT_EQ(costLawText(linear),
              "0.500 + 12.000·Mpx + 0.2500·ktri + 2.000·Mfrag (1.50 fragments a pixel); whole "
              "frame 1.200×");
    PartCost power;
    power.power_coef_ms = 3.5;
    power.px_exponent = 0.75;
    power.tri_exponent = 0.125;
    power.ms_per_mfrag = 2.0;  // not the power law's
    EXPECT_EQ(costLawText(power), "3.5·Mpx^0.750·ktri^0.125");
}

TEST(CalibrationOutput, BitsByFrameTextSplitsAtTheFirstSecond) {
    RuntimeCosts c;
    EXPECT_EQ(bitsByFrameText(c), "none (the law alone)");
    c.bits_frame_key.assign(32, 0.0);
    c.bits_frame_middle.assign(32, 1.0);
    c.bits_frame_outer.assign(32, 1.0);
    c.bits_frame_key[10] = 1;
    c.bits_frame_middle[10] = 1.2;
    c.bits_frame_outer[10] = 0.8;
    c.bits_frame_key[11] = 2;
    c.bits_frame_middle[11] = 1.0;
    c.bits_frame_outer[11] = 1.0;
    EXPECT_EQ(bitsByFrameText(c),
              "frames < 30, 2 frames: middle 1.100x [1.00, 1.20], outer 0.900x [0.80, 1.00] of "
              "the law");
    c.bits_frame_key[31] = 3;
    c.bits_frame_middle[31] = 2.0;
    EXPECT_EQ(bitsByFrameText(c),
              "frames < 30, 2 frames: middle 1.100x [1.00, 1.20], outer 0.900x [0.80, 1.00]; "
              "frames >= 30, 1 frames: middle 2.000x [2.00, 2.00], outer 1.000x [1.00, 1.00] of "
              "the law");
}

}  // namespace
}  // namespace qvr::experiment
