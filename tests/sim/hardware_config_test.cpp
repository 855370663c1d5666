// Hardware overrides from TOML (sim/hardware.h): keys land where they should, the clock stays
// the caller's, and typos or out-of-range values are errors naming the file.
#include <gtest/gtest.h>

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
