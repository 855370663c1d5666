// A frame's layers as PNG files and the side-by-side display image (compose/layer_files.h):
// what is written is read back the same, a missing layer file is an error naming it.
#include "qvr/compose/layer_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "qvr/compose/test_pattern.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {
namespace {

namespace fs = std::filesystem;

HmdProfile smallProfile() {
    HmdProfile p = defaultHmdProfile();
    p.width_px = 160;
    p.height_px = 180;
    return p;
}

TEST(LayerFiles, NamesEachEyesLayer) {
    EXPECT_EQ(layerPngPath("d", 0, 0), (fs::path("d") / "left_fovea.png").string());
    EXPECT_EQ(layerPngPath("d", 1, 2), (fs::path("d") / "right_outer.png").string());
}

TEST(LayerFiles, WrittenLayersReadBackTheSame) {
    const HmdProfile profile = smallProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 15.0);
    const Pose pose;
    const LayerFrame frame = makeTestPatternFrame(
        profile, plan, pose, 0, renderTestPattern(profile.width_px, profile.height_px));
    const fs::path dir = fs::temp_directory_path() / ("qvr-layers-" + std::to_string(getpid()));
    ASSERT_TRUE(writeLayerPngs((dir / "made").string(), frame));
    auto back = readLayerPngs((dir / "made").string(), plan, pose);
    ASSERT_TRUE(back) << back.error();
    for (size_t eye = 0; eye < 2; ++eye) {
        const ImageRgba8& a = frame.eyes[eye].middle;
        const ImageRgba8& b = back->eyes[eye].middle;
        ASSERT_EQ(a.width(), b.width());
        ASSERT_EQ(a.height(), b.height());
        for (int y = 0; y < a.height(); ++y)
            for (int x = 0; x < a.width() * 4; ++x)
                ASSERT_EQ(a.row(y)[x], b.row(y)[x]);
    }
    auto missing = readLayerPngs((dir / "none").string(), plan, pose);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().find("none"), std::string::npos);
    fs::remove_all(dir);
}

TEST(LayerFiles, SideBySidePutsTheLeftEyeLeft) {
    std::array<ImageRgba8, 2> eyes{ImageRgba8(2, 1), ImageRgba8(2, 1)};
    eyes[0].row(0)[0] = 10;
    eyes[1].row(0)[0] = 20;
    const ImageRgba8 both = sideBySide(eyes);
    ASSERT_EQ(both.width(), 4);
    EXPECT_EQ(both.row(0)[0], 10);
    EXPECT_EQ(both.row(0)[8], 20);
}

}  // namespace
}  // namespace qvr
