#include <gtest/gtest.h>

#include "qvr/experiment/calibration.h"

namespace qvr::experiment {
namespace {

TEST(SpeedProbes, SpreadIsLargestOverSmallestPerSide) {
    EXPECT_EQ(speedProbesSpreadPct({}), (std::array<double, 2>{0.0, 0.0}));
    EXPECT_EQ(speedProbesSpreadPct({{10.0, 20.0}}), (std::array<double, 2>{0.0, 0.0}));
    const auto sp = speedProbesSpreadPct({{10.0, 20.0}, {12.0, 20.0}, {11.0, 25.0}});
    EXPECT_NEAR(sp[0], 20.0, 1e-9);
    EXPECT_NEAR(sp[1], 25.0, 1e-9);
}

TEST(SpeedProbes, TextListsTheProbesAndWarnsWhenUnsteady) {
    EXPECT_EQ(speedProbesText({{10.0, 20.0}}), "10.00/20.00 ms headset/server");
    EXPECT_EQ(speedProbesText({{10.0, 20.0}, {10.5, 20.0}}),
              "10.00/20.00, 10.50/20.00 ms headset/server; spread 5%");
    const std::string unsteady = speedProbesText({{10.0, 20.0}, {10.0, 23.0}});
    EXPECT_EQ(unsteady.rfind("10.00/20.00, 10.00/23.00 ms headset/server; spread 15% (the "
                             "machine was unsteady",
                             0),
              0u)
        << unsteady;
    EXPECT_GT(15.0, kUnsteadySpeedPct);
}

TEST(SpeedProbes, MeanSpeedPerSide) {
    const SpeedSample m = meanSpeed({{10.0, 20.0}, {12.0, 30.0}});
    EXPECT_DOUBLE_EQ(m.headset_ms, 11.0);
    EXPECT_DOUBLE_EQ(m.server_ms, 25.0);
    EXPECT_EQ(meanSpeed({}).headset_ms, 0.0);
}

}  // namespace
}  // namespace qvr::experiment
