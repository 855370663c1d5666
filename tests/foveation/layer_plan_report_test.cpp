// The layer plan's report: JSON keys and values read from the plan, text with every layer.
#include <gtest/gtest.h>

#include "qvr/foveation/layer_plan_report.h"

namespace qvr {
namespace {

TEST(LayerPlanReport, JsonCarriesThePlansNumbers) {
    const HmdProfile profile = defaultHmdProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({5.0, -3.0}, 12.0);
    const nlohmann::json j = layerPlanJson(plan, profile);
    EXPECT_EQ(j["profile"], profile.name);
    EXPECT_DOUBLE_EQ(j["e1_deg"].get<double>(), plan.e1_deg);
    EXPECT_DOUBLE_EQ(j["s2"].get<double>(), plan.s2);
    EXPECT_EQ(j["gaze_deg"][0].get<double>(), 5.0);
    EXPECT_EQ(j["pixels"]["full"].get<int64_t>(), plan.full_pixels);
    EXPECT_EQ(j["eyes"].size(), 2u);
    EXPECT_EQ(j["eyes"][0]["fovea"]["pixels"].get<int64_t>(), plan.eyes[0].fovea.pixels());
    EXPECT_EQ(j["has_remote"].get<bool>(), plan.hasRemote());
}

TEST(LayerPlanReport, TextNamesTheProfileAndEachLayer) {
    const HmdProfile profile = defaultHmdProfile();
    const std::string text = layerPlanText(LayerPlanner(profile).plan({0.0, 0.0}, 15.0), profile);
    EXPECT_EQ(text.rfind("profile " + profile.name + " (1920x2160 per eye", 0), 0u) << text;
    for (const char* layer : {"fovea", "middle", "outer", "full frame"})
        EXPECT_NE(text.find(layer), std::string::npos) << layer;
    EXPECT_NE(text.find("e1 15.00"), std::string::npos) << text;
}

}  // namespace
}  // namespace qvr
