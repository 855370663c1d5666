// One frame's layers rendered to a sink: every non-empty layer of both eyes and a full frame
// each, in order, at the plan's sizes; a sink's error stops the frame.
#include <gtest/gtest.h>

#include "hand_made_scene.h"
#include "qvr/render/frame_layers.h"
#include "render_test_util.h"

namespace qvr {
namespace {

TEST(FrameLayers, RendersEachLayerOfBothEyesIntoTheSink) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    FrameLayersPlan plan;
    plan.profile = test::smallProfile();
    plan.e1_deg = 10.0;
    int images = 0;
    auto sink = [&](Eye eye, const std::string& layer,
                    const ImageRgba8& image) -> Expected<std::string> {
        ++images;
        EXPECT_GT(image.width(), 0) << layer;
        return std::string(eyeName(eye)) + "_" + layer;
    };
    auto frame = renderFrameLayers(test::texturedRoom(), plan, sink);
    ASSERT_TRUE(frame) << frame.error();
    ASSERT_EQ(frame->layers.size(), 8u);  // fovea, middle, outer, full per eye
    EXPECT_EQ(frame->layers[0].layer, "fovea");
    EXPECT_EQ(frame->layers[3].layer, "full");
    EXPECT_EQ(frame->layers[3].width_px, plan.profile.width_px);
    EXPECT_EQ(frame->layers[7].file, "right_full");
    int rendered = 0;
    for (const FrameLayer& l : frame->layers)
        rendered += l.empty ? 0 : 1;
    EXPECT_EQ(images, rendered);
    const nlohmann::json j = frameLayersJson(*frame);
    EXPECT_EQ(j["layers"].size(), static_cast<size_t>(rendered));
    EXPECT_NE(frameLayersText(*frame).find("right full"), std::string::npos);
}

TEST(FrameLayers, ASinkErrorStopsTheFrame) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    FrameLayersPlan plan;
    plan.profile = test::smallProfile();
    auto frame =
        renderFrameLayers(test::texturedRoom(), plan,
                          [](Eye, const std::string&, const ImageRgba8&) -> Expected<std::string> {
                              return makeError("disk full");
                          });
    ASSERT_FALSE(frame);
    EXPECT_EQ(frame.error(), "disk full");
}

}  // namespace
}  // namespace qvr
