// The OpenGL renderer on Mesa's surfaceless EGL: context creation, geometry landing where the
// pinhole projection puts it, layers that are pieces of the full frame at their own scale, and
// primitive counts that match what the CPU submitted.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include <glm/geometric.hpp>

#include "hand_made_scene.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/render/gl_renderer.h"
#include "render_test_util.h"

namespace qvr {
namespace {

bool isRed(const uint8_t* p) {
    return p[0] > 200 && p[1] < 60 && p[2] < 60;
}

// One 6 cm red square facing the eye, `distance_m` along the eye-space direction `dir`.
Scene redMarker(const Pose& eye_pose, const glm::dvec3& dir, double distance_m) {
    Scene s;
    s.name = "test:marker";
    const glm::vec3 d = glm::normalize(eye_pose.orientation * glm::vec3(dir));
    const glm::vec3 c = eye_pose.position_m + d * static_cast<float>(distance_m);
    const glm::vec3 right =
        glm::normalize(glm::cross(d, eye_pose.orientation * glm::vec3(0, 1, 0)));
    const glm::vec3 up = glm::cross(right, d);
    const float h = 0.03f;
    test::addQuad(s, c - right * h - up * h, c + right * h - up * h, c + right * h + up * h,
                  c - right * h + up * h, -1, -1, {255, 0, 0, 255});
    return s;
}

TEST(GlRenderer, CreatesAnOpenGl45CoreContextThroughEgl) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const GlInfo& info = gl->info();
    int major = 0, minor = 0;
    ASSERT_EQ(std::sscanf(info.version.c_str(), "%d.%d", &major, &minor), 2) << info.version;
    EXPECT_GE(major * 10 + minor, 45) << info.version;
    EXPECT_FALSE(info.renderer.empty());
    EXPECT_GE(info.max_framebuffer_px, 2160);
    std::printf("EGL platform %s, GL %s on %s, pipeline statistics %s\n", info.egl_platform.c_str(),
                info.version.c_str(), info.renderer.c_str(),
                info.pipeline_statistics ? "yes" : "no");
}

TEST(GlRenderer, QuadLandsAtThePixelTheProjectionPredicts) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const HmdProfile profile = test::smallProfile();
    const EyeGeometry geometry(profile);
    Pose head;
    head.orientation = quatFromEulerDeg({20.0, 5.0, 3.0});
    head.position_m = {1.0f, 2.0f, 3.0f};
    const double px = 210.0, py = 95.0;
    const Pose ep = eyePose(head, Eye::kLeft, 0.064);
    ASSERT_TRUE(gl->upload(redMarker(ep, geometry.directionAt(px, py), 2.0)));

    ImageRgba8 full;
    auto stats = gl->render(fullFrameView(profile, head, Eye::kLeft), full);
    ASSERT_TRUE(stats) << stats.error();
    const test::Centroid c = test::centroidOf(full, isRed);
    ASSERT_GT(c.count, 4);
    EXPECT_NEAR(c.x, px, 0.75);
    EXPECT_NEAR(c.y, py, 0.75);
    EXPECT_EQ(full.at(10, 10, 0), kClearRgba[0]);

    // The same marker in a layer at scale 2.5 whose rect holds it, off the image centre.
    LayerRect l;
    l.rect = {150, 40, 290, 200};
    l.scale = 2.5;
    l.width_px = 56;
    l.height_px = 64;
    ImageRgba8 layer;
    ASSERT_TRUE(gl->render(layerView(profile, head, Eye::kLeft, l), layer));
    const test::Centroid lc = test::centroidOf(layer, isRed);
    ASSERT_GT(lc.count, 0);
    EXPECT_NEAR(l.rect.x0 + lc.x * l.scale, px, 0.75 * l.scale);
    EXPECT_NEAR(l.rect.y0 + lc.y * l.scale, py, 0.75 * l.scale);
}

TEST(GlRenderer, EyesSeeANearObjectWithTheDisparityOfTheIpd) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const HmdProfile profile = test::smallProfile();
    const Pose head;
    // Straight ahead of the head centre at 1 m: each eye sees it fx·(ipd/2)/1 px off centre.
    Pose centre = head;
    ASSERT_TRUE(gl->upload(redMarker(centre, {0, 0, -1}, 1.0)));
    ImageRgba8 left, right;
    ASSERT_TRUE(gl->render(fullFrameView(profile, head, Eye::kLeft), left));
    ASSERT_TRUE(gl->render(fullFrameView(profile, head, Eye::kRight), right));
    const double offset = profile.focalXPx() * 0.032;
    const test::Centroid cl = test::centroidOf(left, isRed);
    const test::Centroid cr = test::centroidOf(right, isRed);
    EXPECT_NEAR(cl.x, 160.0 + offset, 0.75);
    EXPECT_NEAR(cr.x, 160.0 - offset, 0.75);
    EXPECT_NEAR(cl.y, 180.0, 0.75);
    EXPECT_NEAR(cr.y, 180.0, 0.75);
}

class GlLayers : public ::testing::Test {
protected:
    void render(GlRenderer* gl) {
        ASSERT_TRUE(gl->upload(test::texturedRoom()));
        head.orientation = quatFromEulerDeg({12.0, -8.0, 0.0});
        head.position_m = {0.3f, 0.2f, 0.5f};
        plan = LayerPlanner(profile).plan({6.0, -4.0}, 12.0);
        auto s = gl->render(fullFrameView(profile, head, Eye::kRight), full);
        ASSERT_TRUE(s) << s.error();
    }
    HmdProfile profile = test::smallProfile();
    Pose head;
    LayerPlan plan;
    ImageRgba8 full;
};

TEST_F(GlLayers, FoveaLayerIsTheFullFramesRectAtFullResolution) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    render(gl);
    const LayerRect& fovea = plan.eyes[1].fovea;
    ASSERT_EQ(fovea.scale, 1.0);
    ImageRgba8 layer;
    ASSERT_TRUE(gl->render(layerView(profile, head, Eye::kRight, fovea), layer));
    // Same pixel centres through a different (off-axis) matrix: equal up to rounding of the
    // interpolants.
    const double psnr = test::psnrDb(
        layer, test::crop(full, fovea.rect.x0, fovea.rect.y0, layer.width(), layer.height()));
    EXPECT_GT(psnr, 40.0);
    std::printf("fovea %dx%d vs full-frame crop: PSNR %.1f dB\n", layer.width(), layer.height(),
                psnr);
}

TEST_F(GlLayers, MiddleAndOuterLayersAreTheFullFrameDownsampledAndLineUp) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    render(gl);
    for (LayerKind kind : {LayerKind::kMiddle, LayerKind::kOuter}) {
        const LayerRect& l = layerOf(plan.eyes[1], kind);
        ASSERT_GT(l.scale, 1.5) << layerName(kind);
        ImageRgba8 layer;
        ASSERT_TRUE(gl->render(layerView(profile, head, Eye::kRight, l), layer));
        ASSERT_EQ(layer.width(), l.width_px);
        const double aligned = test::psnrDb(
            layer,
            test::areaDownsample(full, l.rect.x0, l.rect.y0, l.scale, l.width_px, l.height_px));
        // A layer shifted by one texel against the reference must match worse in every
        // direction: the rect's edges map onto the frame where UCA expects them.
        double best_shifted = 0.0;
        for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
            const double shifted =
                test::psnrDb(layer, test::areaDownsample(full, l.rect.x0 + dx * l.scale,
                                                         l.rect.y0 + dy * l.scale, l.scale,
                                                         l.width_px, l.height_px));
            best_shifted = std::max(best_shifted, shifted);
        }
        std::printf("%s %dx%d at scale %.2f: PSNR %.1f dB aligned, %.1f dB best one-texel shift\n",
                    layerName(kind), l.width_px, l.height_px, l.scale, aligned, best_shifted);
        EXPECT_GT(aligned, 25.0) << layerName(kind);
        EXPECT_GT(aligned, best_shifted + 3.0) << layerName(kind);
    }
}

TEST(GlRenderer, PrimitivesGeneratedEqualTheTrianglesSubmitted) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const Scene room = test::texturedRoom();
    const HmdProfile profile = test::smallProfile();
    auto null_renderer = makeNullRenderer();
    ASSERT_TRUE(gl->upload(room));
    ASSERT_TRUE(null_renderer->upload(room));
    ImageRgba8 a, b;
    for (double yaw : {0.0, 60.0, 180.0, 250.0}) {
        Pose head;
        head.orientation = quatFromEulerDeg({yaw, 10.0, 0.0});
        const RenderView v = fullFrameView(profile, head, Eye::kLeft);
        auto g = gl->render(v, a);
        auto n = null_renderer->render(v, b);
        ASSERT_TRUE(g) << g.error();
        ASSERT_TRUE(n);
        EXPECT_EQ(g->primitives_generated, n->primitives_generated) << "yaw " << yaw;
        EXPECT_EQ(g->clusters_drawn, n->clusters_drawn);
        EXPECT_EQ(g->draw_calls, n->draw_calls);
        if (gl->info().pipeline_statistics) {
            EXPECT_EQ(g->clipping_input_primitives, g->primitives_generated);
        }
        EXPECT_GE(g->gpu_ms, 0.0);
    }
}

// The fovea law charges the fragments a pass shades (calibration version 16): every covered pixel
// is shaded at least once, the count is the same for the same view, and it follows the view's
// content, not only its size.
TEST(GlRenderer, FragmentInvocationsCoverEveryDrawnPixelAndAreDeterministic) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    if (!gl->info().pipeline_statistics)
        GTEST_SKIP() << "the driver has no ARB_pipeline_statistics_query";
    const Scene room = test::texturedRoom();
    const HmdProfile profile = test::smallProfile();
    ASSERT_TRUE(gl->upload(room));
    ImageRgba8 img;
    std::vector<uint64_t> counts;
    for (double yaw : {0.0, 0.0, 90.0}) {
        Pose head;
        head.orientation = quatFromEulerDeg({yaw, 10.0, 0.0});
        const RenderView v = fullFrameView(profile, head, Eye::kLeft);
        auto g = gl->render(v, img);
        ASSERT_TRUE(g) << g.error();
        uint64_t covered = 0;
        for (int y = 0; y < img.height(); ++y)
            for (int x = 0; x < img.width(); ++x) {
                const uint8_t* p = img.row(y) + 4 * x;
                covered +=
                    !(p[0] == kClearRgba[0] && p[1] == kClearRgba[1] && p[2] == kClearRgba[2]);
            }
        std::printf("yaw %.0f: %llu fragments for %llu covered of %d pixels\n", yaw,
                    static_cast<unsigned long long>(g->fragment_invocations),
                    static_cast<unsigned long long>(covered), img.width() * img.height());
        EXPECT_GT(covered, 0u);
        EXPECT_TRUE(g->statistics);  // a count, where 0 would mean none shaded
        EXPECT_GE(g->fragment_invocations, covered) << "yaw " << yaw;
        counts.push_back(g->fragment_invocations);
    }
    EXPECT_EQ(counts[0], counts[1]);
}

TEST(GlRenderer, MalformedScenesAreErrorsNotCrashes) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    Scene bad_index = test::texturedRoom();
    bad_index.indices[4] = 100000;
    auto s1 = gl->upload(bad_index);
    ASSERT_FALSE(s1);
    EXPECT_NE(s1.error().find("vertex index"), std::string::npos) << s1.error();

    Scene bad_texture = test::texturedRoom();
    bad_texture.textures[1].rgba.resize(10);
    EXPECT_FALSE(gl->upload(bad_texture));

    Scene bad_batch = test::texturedRoom();
    bad_batch.batches[2].first_index = static_cast<uint32_t>(bad_batch.indices.size());
    EXPECT_FALSE(gl->upload(bad_batch));

    Scene bad_lightmap = test::texturedRoom();
    bad_lightmap.batches[0].lightmap = 5;
    EXPECT_FALSE(gl->upload(bad_lightmap));

    // The renderer stays usable, and an empty view is no error.
    ASSERT_TRUE(gl->upload(test::texturedRoom()));
    ImageRgba8 img;
    EXPECT_TRUE(gl->render(RenderView{}, img));
    EXPECT_TRUE(gl->render(fullFrameView(test::smallProfile(), Pose{}, Eye::kLeft), img));
}

TEST(GlRenderer, ShadingIsTextureTimesLightmapTimesVertexColour) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    // A flat grey texture under a flat half-bright lightmap and a blue-ish vertex colour,
    // filling the whole view.
    Scene s;
    SceneTexture tex;
    tex.name = "grey";
    tex.width = tex.height = 4;
    tex.rgba.assign(64, 200);
    SceneTexture lm = tex;
    lm.name = "half";
    std::fill(lm.rgba.begin(), lm.rgba.end(), uint8_t{128});
    s.textures.push_back(tex);
    s.lightmaps.push_back(lm);
    test::addQuad(s, {-10, -10, -1}, {10, -10, -1}, {10, 10, -1}, {-10, 10, -1}, 0, 0,
                  {255, 128, 64, 255});
    ASSERT_TRUE(gl->upload(s));
    ImageRgba8 img;
    ASSERT_TRUE(gl->render(fullFrameView(test::smallProfile(), Pose{}, Eye::kLeft), img));
    const double expect[3] = {200.0 * 128 / 255, 200.0 * 128 / 255 * 128 / 255,
                              200.0 * 128 / 255 * 64 / 255};
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.at(160, 180, c), expect[c], 2.0) << "channel " << c;
    EXPECT_EQ(img.at(160, 180, 3), 255);
}

}  // namespace
}  // namespace qvr

namespace qvr {
namespace {

// The renderer keeps one framebuffer per sample count that only grows, and draws each view
// into its corner: a view rendered after a larger one is, pixel for pixel, what a renderer that
// never drew the larger one renders (the clear and the multisample resolve stay in the corner).
TEST(GlRenderer, AViewAfterALargerOneIsWhatAFreshRendererDraws) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    for (int samples : {1, 4}) {
        if (gl->info().max_samples < samples)
            continue;
        GlRendererOptions options;
        options.msaa_samples = samples;
        auto used = GlRenderer::create(options);
        auto fresh = GlRenderer::create(options);
        ASSERT_TRUE(used && fresh);
        const HmdProfile profile = test::smallProfile();
        Pose head;
        head.orientation = quatFromEulerDeg({12.0, -8.0, 0.0});
        ASSERT_TRUE((*used)->upload(test::texturedRoom()));
        ASSERT_TRUE((*fresh)->upload(test::texturedRoom()));
        LayerRect l;
        l.rect = {150, 40, 290, 200};
        l.scale = 2.5;
        l.width_px = 56;
        l.height_px = 64;
        ImageRgba8 large, after, alone;
        ASSERT_TRUE((*used)->render(fullFrameView(profile, head, Eye::kLeft), large));
        ASSERT_TRUE((*used)->render(layerView(profile, head, Eye::kLeft, l), after));
        ASSERT_TRUE((*fresh)->render(layerView(profile, head, Eye::kLeft, l), alone));
        ASSERT_EQ(after.width(), 56);
        ASSERT_EQ(after.height(), 64);
        ASSERT_EQ(alone.width(), 56);
        int differ = 0;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 56; ++x)
                for (int c = 0; c < 4; ++c)
                    differ += after.at(x, y, c) != alone.at(x, y, c);
        EXPECT_EQ(differ, 0) << samples << " samples";
        // And the larger view again, drawn into the same storage, is what it was.
        ImageRgba8 again;
        ASSERT_TRUE((*used)->render(fullFrameView(profile, head, Eye::kLeft), again));
        int changed = 0;
        for (int y = 0; y < large.height(); ++y)
            for (int x = 0; x < large.width(); ++x)
                changed += again.at(x, y, 0) != large.at(x, y, 0);
        EXPECT_EQ(changed, 0) << samples << " samples";
    }
}

TEST(GlRenderer, MultisamplingBlendsEdgesAndASecondContextCoexists) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    GlRendererOptions options;
    options.msaa_samples = 4;
    if (gl->info().max_samples < 4)
        GTEST_SKIP() << "driver offers " << gl->info().max_samples << " samples";
    auto msaa = GlRenderer::create(options);
    ASSERT_TRUE(msaa) << msaa.error();
    // A flat red square rotated 30° about the view axis: without multisampling every pixel is
    // either red or the clear colour; with it the edge pixels fall in between.
    Scene s;
    const glm::quat r = glm::angleAxis(0.52f, glm::vec3(0, 0, 1));
    test::addQuad(s, r * glm::vec3(-1, -1, -4), r * glm::vec3(1, -1, -4), r * glm::vec3(1, 1, -4),
                  r * glm::vec3(-1, 1, -4), -1, -1, {255, 0, 0, 255});
    const RenderView view = fullFrameView(test::smallProfile(), Pose{}, Eye::kLeft);
    auto mixed = [](const ImageRgba8& img) {
        int n = 0;
        for (int y = 0; y < img.height(); ++y) {
            for (int x = 0; x < img.width(); ++x) {
                const int red = img.at(x, y, 0);
                if (red != 255 && red != kClearRgba[0])
                    ++n;
            }
        }
        return n;
    };
    ImageRgba8 single, multi;
    ASSERT_TRUE(gl->upload(s));
    ASSERT_TRUE((*msaa)->upload(s));
    ASSERT_TRUE(gl->render(view, single));
    ASSERT_TRUE((*msaa)->render(view, multi));
    EXPECT_EQ(mixed(single), 0);
    EXPECT_GT(mixed(multi), 100);
    EXPECT_EQ(multi.at(160, 180, 0), 255);
    // The first renderer still works after the second one is gone.
    msaa = Error{"released"};
    ASSERT_TRUE(gl->render(view, single));
    EXPECT_EQ(single.at(160, 180, 0), 255);

    options.msaa_samples = 1000;
    auto too_many = GlRenderer::create(options);
    ASSERT_FALSE(too_many);
    EXPECT_NE(too_many.error().find("samples"), std::string::npos);
}

}  // namespace
}  // namespace qvr

namespace qvr {
namespace {

// A machine without an EGL driver must get a message, not a crash or a hang. GLVND reads
// __EGL_VENDOR_LIBRARY_FILENAMES once per process, so the child of a thread-safe death test
// (a fresh process running only this test) sets it before its first EGL call.
TEST(GlRendererDeathTest, NoEglDriverIsAClearErrorNotACrashOrHang) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(
        {
            setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json", 1);
            auto r = GlRenderer::create();
            std::fprintf(stderr, "%s\n", r ? "created" : r.error().c_str());
            std::exit(r ? 0 : 3);
        },
        ::testing::ExitedWithCode(3), "EGL: .*libegl-mesa0");
}

}  // namespace
}  // namespace qvr
