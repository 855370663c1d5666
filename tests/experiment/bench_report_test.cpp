// The reports of `qvr bench render|uca`, read from hand-made results.
#include <gtest/gtest.h>

#include "qvr/experiment/render_bench.h"
#include "qvr/experiment/uca_bench_report.h"

namespace qvr::experiment {
namespace {

RenderBenchResult renderResult() {
    RenderBenchResult r;
    r.plan.profile = defaultHmdProfile();
    r.renderer = "test";
    RenderBenchSceneResult s;
    s.scene = "builtin:room";
    RenderBenchLayer fovea;
    fovea.name = "fovea";
    fovea.render_ms_median = 2.0;
    fovea.views = 10;
    s.layers = {fovea};
    s.layers_sum_ms_per_eye = 2.0;
    s.full_ms_per_eye = 6.0;
    r.scenes = {s};
    return r;
}

TEST(RenderBenchReport, JsonPerSceneAndLayer) {
    const nlohmann::json j = renderBenchJson(renderResult());
    ASSERT_EQ(j["scenes"].size(), 1u);
    EXPECT_EQ(j["scenes"][0]["scene"], "builtin:room");
    EXPECT_EQ(j["scenes"][0]["layers"]["fovea"]["views"].get<int>(), 10);
    EXPECT_FALSE(j["scenes"][0]["layers"].contains("middle"));
    EXPECT_EQ(j["width_px"].get<int>(), 1920);
}

TEST(RenderBenchReport, TextComparesTheLayersWithTheFullFrame) {
    const std::string text = renderBenchText(renderResult());
    EXPECT_NE(text.find("LP_NUM_THREADS unset (all cores)"), std::string::npos) << text;
    EXPECT_NE(text.find("2.00 ms per eye vs full frame 6.00 ms (3.00x)"), std::string::npos)
        << text;
}

TEST(UcaBenchReport, QualityOnlyWhenMeasuredAndOpenCvOnlyWhenRun) {
    UcaBenchOptions o;
    o.quality = false;
    UcaBenchResult b;
    b.uca_ms = b.uca_min_ms = 1.0;
    b.two_pass_ms = b.two_pass_min_ms = 3.0;
    b.bandwidth_floor_ms = b.bandwidth_floor_min_ms = 0.5;
    nlohmann::json j = ucaBenchJson(o, b);
    EXPECT_FALSE(j.contains("quality"));
    EXPECT_FALSE(j.contains("opencv_two_pass_ms"));
    EXPECT_EQ(j["config"]["eyes"].get<int>(), 2);
    std::string text = ucaBenchText(o, b);
    EXPECT_NE(text.find("UCA speed-up 3.00x"), std::string::npos) << text;
    EXPECT_NE(text.find("OpenCV two-pass    not built"), std::string::npos) << text;
    EXPECT_EQ(text.find("PSNR"), std::string::npos) << text;
    o.quality = true;
    b.opencv_two_pass_ms = b.opencv_two_pass_min_ms = 2.0;
    b.opencv_quality = QualityReport{};
    j = ucaBenchJson(o, b);
    EXPECT_TRUE(j["quality"].contains("opencv_two_pass"));
    EXPECT_FALSE(j["quality_vs_layers"].contains("opencv_two_pass"));
    text = ucaBenchText(o, b);
    EXPECT_NE(text.find("OpenCV two-pass        2.00"), std::string::npos) << text;
    EXPECT_NE(text.find("  OpenCV    PSNR"), std::string::npos) << text;
}

}  // namespace
}  // namespace qvr::experiment
