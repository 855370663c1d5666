// Hardware overrides from TOML (sim/hardware.h): keys land where they should, the clock stays
// the caller's, and typos or out-of-range values are errors naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string_view>
#include <type_traits>
#include <variant>

#include "qvr/sim/hardware.h"

namespace qvr {
namespace {

TEST(HardwareConfig, OverridesOnlyTheKeysGiven) {
    auto hw = parseHardwareConfig(
        "[uca]\nunits = 4\ncycles_per_tile = 266\n[gpu]\ntexture_units = 16\n"
        "[latency]\ndisplay_ms = 3.5\n",
        "headset.toml", 400.0);
    ASSERT_TRUE(hw.ok()) << hw.error();
    EXPECT_EQ(hw->uca.units, 4);
    EXPECT_EQ(hw->uca.cycles_per_tile, 266.0);
    EXPECT_EQ(hw->gpu.texture_units, 16.0);
    EXPECT_EQ(hw->fixed.display_ms, 3.5);
    EXPECT_EQ(hw->gpu.render.freq_mhz, 400.0);
    const HardwareConfig def = defaultHardware(400.0);
    EXPECT_EQ(hw->fixed.sensor_ms, def.fixed.sensor_ms);
    EXPECT_EQ(hw->uca.power_w, def.uca.power_w);
    // 4 units at half the cycles: a quarter of the default wall time per tile.
    EXPECT_NEAR(hw->uca.wallMs(100.0), def.uca.wallMs(100.0) / 4.0, 1e-12);
}

TEST(HardwareConfig, RejectsUnknownKeysBadValuesAndBadToml) {
    for (const char* bad :
         {"[uca]\nunit = 4\n", "[gpu]\ntexture_units = 0\n", "[cpu]\ncontrol_logic_ms = -1\n",
          "[remote]\nserver_speedup = \"x\"\n", "[latency\n", "[warp]\ndrive = 9\n"}) {
        auto hw = parseHardwareConfig(bad, "bad.toml", 500.0);
        EXPECT_FALSE(hw.ok()) << bad;
        if (!hw.ok()) {
            EXPECT_NE(hw.error().find("bad.toml"), std::string::npos) << hw.error();
        }
    }
    EXPECT_FALSE(loadHardwareConfig("/nonexistent/hw.toml", 500.0).ok());
}

}  // namespace
}  // namespace qvr

namespace qvr {
namespace {

TEST(HardwareConfig, RuntimeSectionRoundTripsAndRejectsBadValues) {
    RuntimeCosts c;
    c.fovea = {3.5, 41.0, 0.125};
    c.decode = {0.25, 6.0, 0.0};
    c.server_frame_ms = 1.5;
    c.packet_overhead_bytes = 60.0;
    c.bits_per_px_at_1 = 0.3;
    c.bits_scale_exponent = 0.25;
    c.bits_outer_per_px_at_1 = 0.125;
    c.bits_outer_scale_exponent = 0.5;
    c.bits_full_frame_per_px = 0.0625;
    c.canvas_align_px = 8;
    c.canvas_headroom = 0.25;
    c.canvas_shrink_ratio = 0.375;
    c.canvas_shrink_after_frames = 12;
    c.keyint_frames = 60;
    c.keyframe_bits_ratio = 6.5;
    c.keyframe_outer_bits_ratio = 5.25;
    c.keyframe_periodic_bits_ratio = 3.5;
    c.padding_bits_ratio = 0.5;
    c.corun_slowdown = 1.125;
    c.corun_headset_slowdown = 1.25;
    c.corun_server_slowdown = 1.0625;
    c.server_render.power_coef_ms = 3.5;
    c.server_render.px_exponent = 0.5;
    c.server_render.tri_exponent = 0.75;
    c.server_render.full_frame_scale = 1.75;
    c.fovea.full_frame_scale = 0.875;
    c.encode.full_frame_scale = 0.625;
    c.server_render.ms_per_mfrag = 18.5;
    c.server_render.frag_per_px = 2.75;
    c.scanout_record_ms = 1.25;
    c.speed_reference_headset_ms = 9.5;
    c.speed_reference_server_ms = 21.25;
    c.speed_reference_key = "0123456789abcdef";
    c.bits_frame_key = {0.0, 4294967295.0, 17.0};
    c.bits_frame_middle = {1.0, 1.25, 0.875};
    c.bits_frame_outer = {1.0, 0.5, 19.5};
    auto hw = parseHardwareConfig(runtimeCostsToml(c), "cal.toml", 500.0);
    ASSERT_TRUE(hw.ok()) << hw.error();
    EXPECT_TRUE(hw->runtime_pipeline);
    EXPECT_EQ(hw->runtime.fovea.base_ms, 3.5);
    EXPECT_EQ(hw->runtime.fovea.ms_per_mpx, 41.0);
    EXPECT_EQ(hw->runtime.fovea.ms_per_ktri, 0.125);
    EXPECT_EQ(hw->runtime.decode.ms_per_mpx, 6.0);
    EXPECT_EQ(hw->runtime.server_frame_ms, 1.5);
    EXPECT_EQ(hw->runtime.packet_overhead_bytes, 60.0);
    EXPECT_EQ(hw->runtime.bits_outer_per_px_at_1, 0.125);
    EXPECT_EQ(hw->runtime.bits_outer_scale_exponent, 0.5);
    EXPECT_EQ(hw->runtime.bits_full_frame_per_px, 0.0625);
    EXPECT_EQ(hw->runtime.canvas_align_px, 8);
    EXPECT_EQ(hw->runtime.canvas_headroom, 0.25);
    EXPECT_EQ(hw->runtime.canvas_shrink_ratio, 0.375);
    EXPECT_EQ(hw->runtime.canvas_shrink_after_frames, 12);
    EXPECT_EQ(hw->runtime.keyint_frames, 60);
    EXPECT_EQ(hw->runtime.keyframe_bits_ratio, 6.5);
    EXPECT_EQ(hw->runtime.keyframe_outer_bits_ratio, 5.25);
    EXPECT_EQ(hw->runtime.keyframe_periodic_bits_ratio, 3.5);
    EXPECT_EQ(hw->runtime.padding_bits_ratio, 0.5);
    EXPECT_EQ(hw->runtime.corun_slowdown, 1.125);
    EXPECT_EQ(hw->runtime.corun_headset_slowdown, 1.25);
    EXPECT_EQ(hw->runtime.corun_server_slowdown, 1.0625);
    EXPECT_EQ(hw->runtime.scanout_record_ms, 1.25);
    EXPECT_EQ(hw->runtime.speed_reference_headset_ms, 9.5);
    EXPECT_EQ(hw->runtime.speed_reference_server_ms, 21.25);
    EXPECT_EQ(hw->runtime.speed_reference_key, "0123456789abcdef");
    EXPECT_EQ(hw->runtime.bits_frame_key, c.bits_frame_key);
    EXPECT_EQ(hw->runtime.bits_frame_middle, c.bits_frame_middle);
    EXPECT_EQ(hw->runtime.bits_frame_outer, c.bits_frame_outer);
    EXPECT_EQ(hw->runtime.bitsFrameFactor(1, 4294967295u, false), 1.25);
    EXPECT_EQ(hw->runtime.bitsFrameFactor(1, 4294967295u, true), 0.5);
    EXPECT_EQ(hw->runtime.bitsFrameFactor(1, 16u, true), 1.0);   // another pose: the law
    EXPECT_EQ(hw->runtime.bitsFrameFactor(0, 0u, false), 1.0);   // not measured
    EXPECT_EQ(hw->runtime.bitsFrameFactor(3, 17u, false), 1.0);  // past the frames measured
    // Without frame-by-frame bits (a calibration before version 15) none are written.
    RuntimeCosts law_only = c;
    law_only.bits_frame_key.clear();
    EXPECT_EQ(runtimeCostsToml(law_only).find("bits_frame"), std::string::npos);
    // Without a speed reference (a calibration before version 14) none is written or read.
    RuntimeCosts no_speed = c;
    no_speed.speed_reference_headset_ms = 0.0;
    EXPECT_EQ(runtimeCostsToml(no_speed).find("speed_reference"), std::string::npos);
    // A render part's power law and whole-frame scale.
    EXPECT_EQ(hw->runtime.server_render.power_coef_ms, 3.5);
    EXPECT_EQ(hw->runtime.server_render.px_exponent, 0.5);
    EXPECT_EQ(hw->runtime.server_render.tri_exponent, 0.75);
    EXPECT_EQ(hw->runtime.server_render.full_frame_scale, 1.75);
    EXPECT_EQ(hw->runtime.encode.full_frame_scale, 0.625);
    EXPECT_DOUBLE_EQ(hw->runtime.server_render.at(4e6, 9e3), 3.5 * 2.0 * std::pow(9.0, 0.75));
    EXPECT_DOUBLE_EQ(hw->runtime.server_render.atFullFrame(4e6, 9e3),
                     1.75 * 3.5 * 2.0 * std::pow(9.0, 0.75));
    EXPECT_EQ(hw->runtime.fovea.power_coef_ms, 0.0);  // linear: the law above
    EXPECT_DOUBLE_EQ(hw->runtime.fovea.atFullFrame(1e6, 8e3), 0.875 * (3.5 + 41.0 + 1.0));
    // A fragments term (version 16) reads back; without one (fovea here) none is charged.
    EXPECT_EQ(hw->runtime.server_render.ms_per_mfrag, 18.5);
    EXPECT_EQ(hw->runtime.server_render.frag_per_px, 2.75);
    EXPECT_EQ(hw->runtime.fovea.ms_per_mfrag, 0.0);
    EXPECT_DOUBLE_EQ(hw->runtime.fovea.at(1e6, 8e3, 5e6), 3.5 + 41.0 + 1.0);
    // The middle (and whole frame) read their law, the outer its own; without one, the middle's.
    EXPECT_DOUBLE_EQ(hw->runtime.bitsPerPx(4.0, false), 0.3 * std::pow(4.0, 0.25));
    EXPECT_DOUBLE_EQ(hw->runtime.bitsPerPx(4.0, true), 0.125 * 2.0);
    RuntimeCosts one_law = c;
    one_law.bits_outer_per_px_at_1 = 0.0;
    EXPECT_DOUBLE_EQ(one_law.bitsPerPx(4.0, true), one_law.bitsPerPx(4.0, false));
    EXPECT_FALSE(defaultHardware(500.0).runtime_pipeline);
    auto paper = parseHardwareConfig("[runtime]\npipeline = \"paper\"\n", "p.toml", 500.0);
    ASSERT_TRUE(paper.ok()) << paper.error();
    EXPECT_FALSE(paper->runtime_pipeline);
    for (const char* bad : {"[runtime]\npipeline = \"fast\"\n",
                            "[runtime]\nfovea_base_ms = -1\n",
                            "[runtime]\nuca_per_mpx = 1\n",
                            "[runtime]\npacket_payload_bytes = 0\n",
                            "[runtime]\ndecode_ms_per_mpx = \"x\"\n",
                            "[runtime]\nbits_outer_per_px_at_1 = -0.1\n",
                            "[runtime]\nbits_outer_scale_exponent = 9\n",
                            "[runtime]\nbits_full_frame_per_px = -0.5\n",
                            "[runtime]\nscanout_record_ms = -1\n",
                            "[runtime]\ncanvas_align_px = 7\n",
                            "[runtime]\ncanvas_align_px = 0\n",
                            "[runtime]\ncanvas_headroom = 2\n",
                            "[runtime]\nkeyint_frames = -1\n",
                            "[runtime]\nkeyframe_bits_ratio = -3\n",
                            "[runtime]\npadding_bits_ratio = 11\n",
                            "[runtime]\nkeyframe_periodic_bits_ratio = -1\n",
                            "[runtime]\ncanvas_shrink_after_frames = 0\n",
                            "[runtime]\nfovea_full_frame_scale = 0\n",
                            "[runtime]\nencode_full_frame_scale = 101\n",
                            "[runtime]\nserver_render_px_exponent = 5\n",
                            "[runtime]\ncorun_slowdown = 0.9\n",
                            "[runtime]\ncorun_slowdown = 5\n",
                            "[runtime]\ncorun_headset_slowdown = 0.5\n",
                            "[runtime]\ncorun_server_slowdown = 4.5\n",
                            "[runtime]\nserver_render_power_coef_ms = -2\n",
                            "[runtime]\nfovea_tri_exponent = \"x\"\n",
                            "[runtime]\nfovea_ms_per_mfrag = -1\n",
                            "[runtime]\nfovea_frag_per_px = 1001\n",
                            "[runtime]\nserver_render_frag_per_px = \"deep\"\n",
                            "[runtime]\nspeed_reference_headset_ms = -1\n",
                            "[runtime]\nspeed_reference_server_ms = \"fast\"\n",
                            "[runtime]\nspeed_reference_key = 12\n",
                            "[runtime]\nbits_frame_key = 3\n",
                            "[runtime]\nbits_frame_key = [\"a\"]\n"
                            "bits_frame_middle = [1.0]\nbits_frame_outer = [1.0]\n",
                            "[runtime]\nbits_frame_key = [1.5]\n"
                            "bits_frame_middle = [1.0]\nbits_frame_outer = [1.0]\n",
                            "[runtime]\nbits_frame_key = [-1]\n"
                            "bits_frame_middle = [1.0]\nbits_frame_outer = [1.0]\n",
                            "[runtime]\nbits_frame_key = [4294967296]\n"
                            "bits_frame_middle = [1.0]\nbits_frame_outer = [1.0]\n",
                            "[runtime]\nbits_frame_key = [1, 2]\n"
                            "bits_frame_middle = [1.0]\nbits_frame_outer = [1.0, 1.0]\n",
                            "[runtime]\nbits_frame_key = [1]\n"
                            "bits_frame_middle = [0.01]\nbits_frame_outer = [1.0]\n",
                            "[runtime]\nbits_frame_key = [1]\n"
                            "bits_frame_middle = [1.0]\nbits_frame_outer = [21]\n",
                            "[runtime]\nbits_frame_middle = [1.0]\n"}) {
        auto r = parseHardwareConfig(bad, "bad.toml", 500.0);
        EXPECT_FALSE(r.ok()) << bad;
        if (!r.ok()) {
            EXPECT_NE(r.error().find("bad.toml"), std::string::npos) << r.error();
        }
    }
}

}  // namespace
}  // namespace qvr

namespace qvr {
namespace {

// A value inside the field's range that no default holds, so a key the writer drops or the reader
// ignores shows as a difference.
void setInRange(HardwareField::Ref ref, const HardwareField& f, int k) {
    const double mid = f.min_value + (f.max_value - f.min_value) * (0.25 + 0.5 / (k + 3));
    // Keys written with six significant digits get a value that has no more.
    const bool exact = f.format == "{}";
    const double short_mid =
        f.max_value - f.min_value > 100.0 ? std::round(mid) : std::round(mid * 8.0) / 8.0;
    if (double* const* v = std::get_if<double*>(&ref))
        **v = exact ? mid : short_mid;
    else if (int* const* i = std::get_if<int*>(&ref))
        **i = (static_cast<int>(mid) / 2) * 2 + 2;  // even, above the minimum
    else if (bool* const* b = std::get_if<bool*>(&ref))
        **b = true;
    else if (std::string* const* s = std::get_if<std::string*>(&ref))
        **s = "key" + std::to_string(k);
}

TEST(HardwareFields, EveryFieldRoundTripsThroughTheWriterAndTheReader) {
    HardwareConfig hw = defaultHardware(500.0);
    int k = 0;
    for (const HardwareField& f : hardwareFields())
        setInRange(f.at(hw), f, k++);
    hw.runtime.bits_frame_key = {3.0, 4294967295.0};
    hw.runtime.bits_frame_middle = {1.25, 0.5};
    hw.runtime.bits_frame_outer = {19.5, 0.0625};
    hw.runtime.speed_reference_headset_ms = 9.5;  // both > 0: the speed reference is written
    hw.runtime.speed_reference_server_ms = 21.25;
    const std::string text = hardwareToml(hw);
    auto back = parseHardwareConfig(text, "all.toml", 500.0);
    ASSERT_TRUE(back.ok()) << back.error() << "\n" << text;
    for (const HardwareField& f : hardwareFields()) {
        HardwareConfig a = hw;
        const HardwareField::Ref want = f.at(a), got = f.at(*back);
        std::visit(
            [&](auto* w) {
                using T = std::remove_pointer_t<decltype(w)>;
                EXPECT_EQ(*w, *std::get<T*>(got)) << f.path;
            },
            want);
    }
    // The [runtime] section alone is what the calibration writes.
    const std::string runtime_only = hardwareToml(hw, "runtime");
    EXPECT_EQ(runtime_only.rfind("[runtime]\npipeline = \"runtime\"\n", 0), 0u) << runtime_only;
    EXPECT_EQ(runtime_only.find("[gpu]"), std::string::npos);
    EXPECT_EQ(runtime_only, runtimeCostsToml(hw.runtime));
}

TEST(HardwareFields, ABadValueOfEachKindNamesItsKey) {
    const struct {
        const char* toml;
        const char* key;
    } cases[] = {
        {"[gpu]\nv0 = 3\n", "gpu.v0"},                                    // number out of range
        {"[uca]\ntile_px = 2.5\n", "uca.tile_px"},                        // integer not integral
        {"[uca]\nunits = 65\n", "uca.units"},                             // integer out of range
        {"[runtime]\ncanvas_align_px = 9\n", "runtime.canvas_align_px"},  // not even
        {"[runtime]\npipeline = \"warp\"\n", "runtime.pipeline"},         // not a choice
        {"[runtime]\nspeed_reference_key = 7\n", "runtime.speed_reference_key"},  // not a string
        {"[runtime]\nbits_frame_outer = [1.0, 30.0]\n", "runtime.bits_frame_outer"},  // element
        {"[runtime]\nbits_frame_key = [0.5]\nbits_frame_middle = [1.0]\n"
         "bits_frame_outer = [1.0]\n",
         "runtime.bits_frame_key"},  // not integers
    };
    for (const auto& c : cases) {
        auto r = parseHardwareConfig(c.toml, "bad.toml", 500.0);
        ASSERT_FALSE(r.ok()) << c.toml;
        EXPECT_NE(r.error().find(c.key), std::string::npos) << r.error();
        EXPECT_NE(r.error().find("bad.toml"), std::string::npos) << r.error();
    }
}

TEST(HardwareFields, PathsAreUniqueAndEachReferenceIsInsideTheConfig) {
    HardwareConfig hw;
    const char* lo = reinterpret_cast<const char*>(&hw);
    const char* hi = lo + sizeof(hw);
    std::set<std::string_view> seen;
    for (const HardwareField& f : hardwareFields()) {
        EXPECT_TRUE(seen.insert(f.path).second) << f.path;
        std::visit(
            [&](auto* p) {
                const char* c = reinterpret_cast<const char*>(p);
                EXPECT_TRUE(c >= lo && c < hi) << f.path;
            },
            f.at(hw));
    }
}

}  // namespace
}  // namespace qvr
