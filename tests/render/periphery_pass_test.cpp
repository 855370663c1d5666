// The one-pass periphery (periphery_pass.h): the middle layer's texel grid extended over the
// outer layer, the middle layer cropped out of it exactly, the outer layer its box-filtered
// reduction — checked against hand-computed grids and averages, a 2-D area-average reference on
// random images, and the two-pass rendering of the same plan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "hand_made_scene.h"
#include "qvr/render/periphery_pass.h"
#include "qvr/render/renderer.h"
#include "render_test_util.h"

namespace qvr {
namespace {

LayerRect layerRect(int x0, int y0, int x1, int y1, double scale) {
    LayerRect l;
    l.rect = {x0, y0, x1, y1};
    l.scale = scale;
    l.width_px = static_cast<int>(std::ceil((x1 - x0) / scale));
    l.height_px = static_cast<int>(std::ceil((y1 - y0) / scale));
    return l;
}

ImageRgba8 randomImage(int w, int h, std::mt19937& rng) {
    ImageRgba8 img(w, h);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c)
                img.at(x, y, c) = static_cast<uint8_t>(byte(rng));
    return img;
}

// The outer layer as the exact 2-D area average over the grid image, in doubles: outer texel
// (i, j) covers full-resolution [o.x0 + i·s2, o.x0 + (i+1)·s2) × …, i.e. grid texel coordinates
// [(o.x0 + i·s2 − g.x0)/s1, …); the parts of it past the grid image take the edge texel.
std::vector<double> referenceReduce(const ImageRgba8& grid_image, const PeripheryGrid& grid,
                                    const LayerRect& outer) {
    std::vector<double> out(static_cast<size_t>(outer.width_px) * outer.height_px * 3, 0.0);
    const double step = outer.scale / grid.scale;
    for (int j = 0; j < outer.height_px; ++j) {
        const double y0 = (outer.rect.y0 + j * outer.scale - grid.y0) / grid.scale;
        const double y1 = y0 + step;
        for (int i = 0; i < outer.width_px; ++i) {
            const double x0 = (outer.rect.x0 + i * outer.scale - grid.x0) / grid.scale;
            const double x1 = x0 + step;
            double acc[3] = {0, 0, 0};
            double area = 0.0;
            for (int ky = static_cast<int>(std::floor(y0)); ky < y1; ++ky) {
                const double wy = std::min(y1, ky + 1.0) - std::max(y0, double(ky));
                const int sy = std::clamp(ky, 0, grid_image.height() - 1);
                for (int kx = static_cast<int>(std::floor(x0)); kx < x1; ++kx) {
                    const double wx = std::min(x1, kx + 1.0) - std::max(x0, double(kx));
                    if (wx <= 0.0 || wy <= 0.0)
                        continue;
                    const int sx = std::clamp(kx, 0, grid_image.width() - 1);
                    for (int c = 0; c < 3; ++c)
                        acc[c] += wx * wy * grid_image.at(sx, sy, c);
                    area += wx * wy;
                }
            }
            for (int c = 0; c < 3; ++c)
                out[(static_cast<size_t>(j) * outer.width_px + i) * 3 + c] = acc[c] / area;
        }
    }
    return out;
}

// Every RGB value of `got` within `tolerance` of the reference, alpha 255; the largest error.
double expectNearReference(const ImageRgba8& got, const std::vector<double>& ref,
                           const LayerRect& outer, double tolerance) {
    EXPECT_EQ(got.width(), outer.width_px);
    EXPECT_EQ(got.height(), outer.height_px);
    double worst = 0.0;
    int bad = 0;
    for (int j = 0; j < got.height(); ++j) {
        for (int i = 0; i < got.width(); ++i) {
            for (int c = 0; c < 3; ++c) {
                const double r = ref[(static_cast<size_t>(j) * outer.width_px + i) * 3 + c];
                const double e = std::fabs(got.at(i, j, c) - r);
                worst = std::max(worst, e);
                if (e > tolerance && bad++ < 5)
                    ADD_FAILURE() << "outer texel (" << i << ", " << j << ") channel " << c
                                  << " is " << int(got.at(i, j, c)) << ", the area average " << r;
            }
            if (got.at(i, j, 3) != 255 && bad++ < 5)
                ADD_FAILURE() << "alpha " << int(got.at(i, j, 3)) << " at " << i << ", " << j;
        }
    }
    return worst;
}

// Plans of the small test profile and of the paper's display over several gazes and foveae.
std::vector<std::pair<HmdProfile, LayerPlan>> somePlans() {
    std::vector<std::pair<HmdProfile, LayerPlan>> plans;
    for (const HmdProfile& profile : {test::smallProfile(), HmdProfile{}}) {
        const LayerPlanner planner(profile);
        for (const Gaze gaze : {Gaze{0.0, 0.0}, Gaze{6.0, -4.0}, Gaze{-25.0, 18.0}, Gaze{35, -30}})
            for (double e1 : {5.0, 12.0, 20.0})
                plans.emplace_back(profile, planner.plan(gaze, e1));
    }
    return plans;
}

TEST(PeripheryGrid, HandComputedGridForFractionalScales) {
    EyeLayers e;
    e.outer = layerRect(0, 0, 320, 360, 5.3);  // 61 × 68 texels reaching x 323.3, y 360.4
    e.middle = layerRect(101, 77, 230, 260, 2.2);
    ASSERT_EQ(e.outer.width_px, 61);
    ASSERT_EQ(e.middle.width_px, 59);
    const PeripheryGrid g = peripheryGrid(e);
    // 101 / 2.2 = 45.9 → 46 texels to the left, starting at 101 − 46·2.2 = −0.2; 77 / 2.2 = 35
    // exactly → the grid starts at 0.
    EXPECT_EQ(g.middle_col, 46);
    EXPECT_EQ(g.middle_row, 35);
    EXPECT_NEAR(g.x0, -0.2, 1e-9);
    EXPECT_NEAR(g.y0, 0.0, 1e-9);
    EXPECT_EQ(g.scale, 2.2);
    // (323.3 + 0.2) / 2.2 = 147.05 → 148; 360.4 / 2.2 = 163.8 → 164.
    EXPECT_EQ(g.width_px, 148);
    EXPECT_EQ(g.height_px, 164);
    EXPECT_EQ(g.pixels(), 148 * 164);
}

TEST(PeripheryGrid, MiddleTexelsAreGridTexelsAndTheGridJustCoversTheOuterLayer) {
    int checked = 0;
    for (const auto& [profile, plan] : somePlans()) {
        for (const EyeLayers& e : plan.eyes) {
            const PeripheryGrid g = peripheryGrid(e);
            if (e.middle.empty() || e.outer.empty()) {
                EXPECT_EQ(g.pixels(), 0);
                continue;
            }
            ++checked;
            const LayerRect& m = e.middle;
            const LayerRect& o = e.outer;
            SCOPED_TRACE(::testing::Message() << profile.name << " gaze " << plan.gaze.x_deg << ","
                                              << plan.gaze.y_deg << " e1 " << plan.e1_deg);
            ASSERT_GT(o.scale, m.scale);
            EXPECT_EQ(g.scale, m.scale);
            // Middle texel (i, j) is grid texel (i + middle_col, j + middle_row): same origin.
            EXPECT_NEAR(g.x0 + g.middle_col * g.scale, m.rect.x0, 1e-9);
            EXPECT_NEAR(g.y0 + g.middle_row * g.scale, m.rect.y0, 1e-9);
            EXPECT_GE(g.middle_col, 0);
            EXPECT_GE(g.middle_row, 0);
            EXPECT_LE(g.middle_col + m.width_px, g.width_px);
            EXPECT_LE(g.middle_row + m.height_px, g.height_px);
            // It covers the outer layer's texel grid…
            EXPECT_LE(g.x0, o.rect.x0 + 1e-9);
            EXPECT_LE(g.y0, o.rect.y0 + 1e-9);
            EXPECT_GE(g.x0 + g.width_px * g.scale, o.rect.x0 + o.width_px * o.scale - 1e-9);
            EXPECT_GE(g.y0 + g.height_px * g.scale, o.rect.y0 + o.height_px * o.scale - 1e-9);
            // …with no texel to spare on any side.
            EXPECT_GT(g.x0 + g.scale, o.rect.x0);
            EXPECT_GT(g.y0 + g.scale, o.rect.y0);
            EXPECT_LT(g.x0 + (g.width_px - 1) * g.scale,
                      std::max(o.rect.x0 + o.width_px * o.scale, m.rect.x0 + m.width_px * m.scale));
            EXPECT_LT(
                g.y0 + (g.height_px - 1) * g.scale,
                std::max(o.rect.y0 + o.height_px * o.scale, m.rect.y0 + m.height_px * m.scale));
        }
    }
    EXPECT_GT(checked, 20);
}

TEST(PeripheryGrid, EmptyWithoutAMiddleAndACoarserOuterLayer) {
    EyeLayers both;
    both.outer = layerRect(0, 0, 320, 360, 4.0);
    both.middle = layerRect(100, 100, 200, 220, 2.0);
    ASSERT_GT(peripheryGrid(both).pixels(), 0);
    EyeLayers no_middle = both;
    no_middle.middle = LayerRect{};
    EyeLayers no_outer = both;
    no_outer.outer = LayerRect{};
    EyeLayers same_scale = both;
    same_scale.outer = layerRect(0, 0, 320, 360, 2.0);
    EyeLayers finer_outer = both;
    finer_outer.outer = layerRect(0, 0, 320, 360, 1.5);
    for (const EyeLayers* e : {&no_middle, &no_outer, &same_scale, &finer_outer}) {
        const PeripheryGrid g = peripheryGrid(*e);
        EXPECT_EQ(g.width_px, 0);
        EXPECT_EQ(g.height_px, 0);
        EXPECT_FALSE(onePassPays(*e));
        EXPECT_FALSE(onePassPays(*e, 1e9));
    }
    // A plan whose fovea covers the field has neither layer.
    const LayerPlan all_fovea = LayerPlanner(test::smallProfile()).plan({0.0, 0.0}, 180.0);
    ASSERT_FALSE(all_fovea.hasRemote());
    EXPECT_EQ(peripheryGrid(all_fovea.eyes[0]).pixels(), 0);
}

TEST(PeripheryGrid, OnePassPaysUpToTheFillRatio) {
    EyeLayers e;
    e.outer = layerRect(0, 0, 320, 360, 4.0);       // 80 × 90
    e.middle = layerRect(100, 100, 180, 220, 2.0);  // 40 × 60
    const PeripheryGrid g = peripheryGrid(e);
    ASSERT_EQ(g.pixels(), 160 * 180);  // exactly 3 × (80·90 + 40·60)
    EXPECT_TRUE(onePassPays(e, 3.0));
    EXPECT_TRUE(onePassPays(e, 3.001));
    EXPECT_FALSE(onePassPays(e, 2.999));
    EXPECT_TRUE(onePassPays(e));  // the default 8
}

TEST(PeripheryGrid, AMiddleLayerPastTheOuterOneStaysInsideTheGrid) {
    // Not what the planner makes (its outer layer covers the field), but the grid's contract:
    // the whole middle layer is grid texels.
    EyeLayers e;
    e.outer = layerRect(0, 0, 200, 200, 4.0);
    e.middle = layerRect(150, 160, 262, 270, 2.0);  // 56 × 55 texels, ending at 262, 270
    const PeripheryGrid g = peripheryGrid(e);
    EXPECT_EQ(g.middle_col, 75);
    EXPECT_EQ(g.middle_row, 80);
    EXPECT_EQ(g.width_px, 131);
    EXPECT_EQ(g.height_px, 135);
    EXPECT_LE(g.middle_col + e.middle.width_px, g.width_px);
    EXPECT_LE(g.middle_row + e.middle.height_px, g.height_px);
}

TEST(PeripheryPass, CropMiddleCopiesTheMiddleTexelsOfTheGrid) {
    std::mt19937 rng(7);
    EyeLayers e;
    e.outer = layerRect(0, 0, 320, 360, 5.3);
    e.middle = layerRect(101, 77, 230, 260, 2.2);
    const PeripheryGrid g = peripheryGrid(e);
    const ImageRgba8 grid_image = randomImage(g.width_px, g.height_px, rng);
    ImageRgba8 middle;
    cropMiddle(grid_image, g, e.middle, middle);
    ASSERT_EQ(middle.width(), e.middle.width_px);
    ASSERT_EQ(middle.height(), e.middle.height_px);
    for (int j = 0; j < middle.height(); ++j)
        for (int i = 0; i < middle.width(); ++i)
            for (int c = 0; c < 4; ++c)
                ASSERT_EQ(middle.at(i, j, c), grid_image.at(i + 46, j + 35, c))
                    << "middle texel " << i << ", " << j;
}

TEST(PeripheryPass, ReduceKeepsAConstantImageConstantEvenPastTheGridsEdge) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> frac(0.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
        PeripheryGrid g;
        g.scale = 1.0 + 3.0 * frac(rng);
        g.x0 = -5.0 * frac(rng);
        g.y0 = -5.0 * frac(rng);
        g.width_px = 20 + static_cast<int>(30 * frac(rng));
        g.height_px = 20 + static_cast<int>(30 * frac(rng));
        // The outer layer may start before the grid and reach past it: edge texels take the rest.
        const double s2 = g.scale * (1.05 + 4.0 * frac(rng));
        const LayerRect o =
            layerRect(-static_cast<int>(4 * frac(rng)), -static_cast<int>(4 * frac(rng)),
                      static_cast<int>(g.width_px * g.scale * (0.8 + 0.4 * frac(rng))),
                      static_cast<int>(g.height_px * g.scale * (0.8 + 0.4 * frac(rng))), s2);
        ImageRgba8 grid_image(g.width_px, g.height_px);
        const uint8_t colour[4] = {37, 200, 255, 9};
        for (int y = 0; y < g.height_px; ++y)
            for (int x = 0; x < g.width_px; ++x)
                for (int c = 0; c < 4; ++c)
                    grid_image.at(x, y, c) = colour[c];
        ImageRgba8 out;
        reduceToOuter(grid_image, g, o, out);
        ASSERT_EQ(out.width(), o.width_px);
        ASSERT_EQ(out.height(), o.height_px);
        for (int j = 0; j < out.height(); ++j)
            for (int i = 0; i < out.width(); ++i) {
                for (int c = 0; c < 3; ++c)
                    ASSERT_EQ(out.at(i, j, c), colour[c])
                        << "trial " << trial << " texel " << i << ", " << j;
                ASSERT_EQ(out.at(i, j, 3), 255);
            }
    }
}

TEST(PeripheryPass, ReduceGivesHandComputedAreaAveragesOfAGradient) {
    // One row of grid texels 0, 30, …, 150 at scale 2 from x = 0; outer texels of scale 5.
    PeripheryGrid g;
    g.scale = 2.0;
    g.width_px = 6;
    g.height_px = 1;
    ImageRgba8 grid_image(6, 1);
    for (int x = 0; x < 6; ++x)
        for (int c = 0; c < 3; ++c)
            grid_image.at(x, 0, c) = static_cast<uint8_t>(30 * x + 10 * c);
    // From x = 1: footprints [0.5, 3) and [3, 5.5) in grid texels:
    // (0.5·0 + 30 + 60) / 2.5 = 36 and (90 + 120 + 0.5·150) / 2.5 = 114. The footprint's rows
    // [0, 2.5) reach past the one-row image and take that row.
    LayerRect o;
    o.rect = {1, 0, 11, 5};
    o.scale = 5.0;
    o.width_px = 2;
    o.height_px = 1;
    ImageRgba8 out;
    reduceToOuter(grid_image, g, o, out);
    ASSERT_EQ(out.width(), 2);
    EXPECT_EQ(out.at(0, 0, 0), 36);
    EXPECT_EQ(out.at(1, 0, 0), 114);
    EXPECT_EQ(out.at(0, 0, 2), 56);  // every texel 20 brighter in blue
    EXPECT_EQ(out.at(1, 0, 2), 134);
    // From x = −1, three texels: [−0.5, 2) folds its first half texel onto texel 0,
    // (1.5·0 + 30) / 2.5 = 12; [2, 4.5): (60 + 90 + 0.5·120) / 2.5 = 84; [4.5, 7) folds the
    // texel past the end onto texel 5: (0.5·120 + 150 + 150) / 2.5 = 144.
    o.rect = {-1, 0, 14, 5};
    o.width_px = 3;
    reduceToOuter(grid_image, g, o, out);
    ASSERT_EQ(out.width(), 3);
    EXPECT_EQ(out.at(0, 0, 0), 12);
    EXPECT_EQ(out.at(1, 0, 0), 84);
    EXPECT_EQ(out.at(2, 0, 0), 144);
    EXPECT_EQ(out.at(2, 0, 3), 255);
}

TEST(PeripheryPass, ReduceAveragesACheckerOverWholeTexels) {
    // One-texel checker, 255 where x + y is odd; outer texels of 3 × 3 grid texels average
    // 3 of 9 (even start: 85 + 170 + 85 over 3 rows → 113.3) or 6 of 9 (odd start: 141.7).
    PeripheryGrid g;
    g.scale = 1.5;
    g.width_px = 30;
    g.height_px = 24;
    ImageRgba8 grid_image(30, 24);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 30; ++x)
            for (int c = 0; c < 3; ++c)
                grid_image.at(x, y, c) = (x + y) % 2 != 0 ? 255 : 0;
    LayerRect o;
    o.rect = {0, 0, 45, 36};
    o.scale = 4.5;
    o.width_px = 10;
    o.height_px = 8;
    ImageRgba8 out;
    reduceToOuter(grid_image, g, o, out);
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 10; ++i)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(out.at(i, j, c), (i + j) % 2 == 0 ? 113 : 142) << i << ", " << j;
}

TEST(PeripheryPass, ReduceMatchesTheAreaAverageOnRandomImagesAndPlans) {
    std::mt19937 rng(2024);
    double worst = 0.0;
    int layers = 0;
    for (const auto& [profile, plan] : somePlans()) {
        if (profile.width_px > 400)
            continue;  // the small profile's plans are enough, and fast
        for (const EyeLayers& e : plan.eyes) {
            const PeripheryGrid g = peripheryGrid(e);
            if (g.pixels() == 0)
                continue;
            ++layers;
            const ImageRgba8 grid_image = randomImage(g.width_px, g.height_px, rng);
            ImageRgba8 out;
            reduceToOuter(grid_image, g, e.outer, out);
            worst =
                std::max(worst, expectNearReference(out, referenceReduce(grid_image, g, e.outer),
                                                    e.outer, 0.5 + 1e-3));
        }
    }
    // Hand-made layers with a fractional grid origin, a step that is not a whole number of grid
    // texels, and an outer layer reaching past the grid on every side.
    for (int trial = 0; trial < 10; ++trial) {
        std::uniform_real_distribution<double> frac(0.0, 1.0);
        PeripheryGrid g;
        g.scale = 1.0 + 2.0 * frac(rng);
        g.x0 = 3.0 * frac(rng) - 1.0;
        g.y0 = 3.0 * frac(rng) - 1.0;
        g.width_px = 31;
        g.height_px = 27;
        const LayerRect o =
            layerRect(-3, -2, static_cast<int>(31 * g.scale) + 4,
                      static_cast<int>(27 * g.scale) + 3, g.scale * (1.1 + 3.0 * frac(rng)));
        const ImageRgba8 grid_image = randomImage(g.width_px, g.height_px, rng);
        ImageRgba8 out;
        reduceToOuter(grid_image, g, o, out);
        worst = std::max(
            worst, expectNearReference(out, referenceReduce(grid_image, g, o), o, 0.5 + 1e-3));
        ++layers;
    }
    EXPECT_GT(layers, 15);
    std::printf("reduceToOuter vs double-precision area average: worst %.3f levels\n", worst);
}

TEST(PeripheryPass, AnEyeWithoutBothLayersIsAnError) {
    auto null_renderer = makeNullRenderer();
    ASSERT_TRUE(null_renderer->upload(test::texturedRoom()));
    const HmdProfile profile = test::smallProfile();
    const LayerPlanner planner(profile);
    LayerPlan plan = planner.plan({0.0, 0.0}, 180.0);  // all fovea
    ImageRgba8 middle, outer, scratch;
    auto r =
        renderPeriphery(*null_renderer, profile, plan, Pose{}, Eye::kLeft, middle, outer, scratch);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("middle"), std::string::npos) << r.error();
    plan = planner.plan({6.0, -4.0}, 12.0);
    ASSERT_FALSE(plan.eyes[1].middle.empty());
    ASSERT_FALSE(plan.eyes[1].outer.empty());
    plan.eyes[1].outer = LayerRect{};
    EXPECT_FALSE(renderPeriphery(*null_renderer, profile, plan, Pose{}, Eye::kRight, middle, outer,
                                 scratch));
    // The other eye still works, into images of its layers' sizes.
    auto ok =
        renderPeriphery(*null_renderer, profile, plan, Pose{}, Eye::kLeft, middle, outer, scratch);
    ASSERT_TRUE(ok) << ok.error();
    const PeripheryGrid g = peripheryGrid(plan.eyes[0]);
    EXPECT_EQ(scratch.width(), g.width_px);
    EXPECT_EQ(scratch.height(), g.height_px);
    EXPECT_EQ(middle.width(), plan.eyes[0].middle.width_px);
    EXPECT_EQ(middle.height(), plan.eyes[0].middle.height_px);
    EXPECT_EQ(outer.width(), plan.eyes[0].outer.width_px);
    EXPECT_EQ(outer.height(), plan.eyes[0].outer.height_px);
}

// Fraction of texels whose RGB differs by more than `levels` in some channel.
double fractionDiffering(const ImageRgba8& a, const ImageRgba8& b, int levels) {
    int n = 0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            for (int c = 0; c < 3; ++c)
                if (std::abs(int(a.at(x, y, c)) - int(b.at(x, y, c))) > levels) {
                    ++n;
                    break;
                }
    return double(n) / (double(a.width()) * a.height());
}

TEST(GlPeripheryPass, MiddleIsTheTwoPassMiddleLayerAndOuterTheBoxFilteredFrame) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    ASSERT_TRUE(gl->upload(test::texturedRoom()));
    const HmdProfile profile = test::smallProfile();
    Pose head;
    head.orientation = quatFromEulerDeg({12.0, -8.0, 0.0});
    head.position_m = {0.3f, 0.2f, 0.5f};
    const LayerPlanner planner(profile);
    for (const Gaze gaze : {Gaze{6.0, -4.0}, Gaze{-20.0, 15.0}}) {
        const LayerPlan plan = planner.plan(gaze, 12.0);
        for (Eye eye : {Eye::kLeft, Eye::kRight}) {
            SCOPED_TRACE(::testing::Message()
                         << "gaze " << gaze.x_deg << "," << gaze.y_deg << " eye " << eyeName(eye));
            const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
            ASSERT_TRUE(onePassPays(layers, 1e9));
            const PeripheryGrid g = peripheryGrid(layers);
            ImageRgba8 middle, outer, scratch;
            auto stats = renderPeriphery(*gl, profile, plan, head, eye, middle, outer, scratch);
            ASSERT_TRUE(stats) << stats.error();
            ASSERT_EQ(scratch.width(), g.width_px);
            ASSERT_EQ(scratch.height(), g.height_px);

            // The outputs are the crop and the box reduction of the grid it rendered.
            ASSERT_EQ(middle.width(), layers.middle.width_px);
            ASSERT_EQ(middle.height(), layers.middle.height_px);
            for (int j = 0; j < middle.height(); ++j)
                for (int i = 0; i < middle.width(); ++i)
                    for (int c = 0; c < 4; ++c)
                        ASSERT_EQ(middle.at(i, j, c),
                                  scratch.at(i + g.middle_col, j + g.middle_row, c));
            expectNearReference(outer, referenceReduce(scratch, g, layers.outer), layers.outer,
                                0.5 + 1e-3);

            // The middle layer equals the two-pass one: same texel centres through a larger
            // frustum, so the same coverage; only the rounding of the interpolants differs, which
            // moves texture filtering weights. Measured on llvmpipe: 1.6-6.1 % of texels differ
            // by more than 1 level, 0.6-1.1 % by more than 2, 0.12-0.31 % by more than 4, none
            // by more than 16 (a coverage change on an edge would); PSNR 52-55 dB. A grid off by
            // one texel gives ~20 dB.
            ImageRgba8 two_pass;
            ASSERT_TRUE(renderLayer(*gl, profile, plan, head, eye, LayerKind::kMiddle, two_pass));
            ASSERT_EQ(two_pass.width(), middle.width());
            ASSERT_EQ(two_pass.height(), middle.height());
            const double differ_1 = fractionDiffering(middle, two_pass, 1);
            const double differ_4 = fractionDiffering(middle, two_pass, 4);
            const double differ_16 = fractionDiffering(middle, two_pass, 16);
            const double middle_psnr = test::psnrDb(middle, two_pass);
            EXPECT_LE(differ_16, 0.001);
            EXPECT_LE(differ_4, 0.01);
            EXPECT_GT(middle_psnr, 45.0);

            // The outer layer against the full frame area-averaged onto its grid (the ideal
            // anti-aliased layer), and better aligned than the same average one texel off.
            ImageRgba8 full;
            ASSERT_TRUE(gl->render(fullFrameView(profile, head, eye), full));
            const LayerRect& o = layers.outer;
            const double aligned = test::psnrDb(
                outer,
                test::areaDownsample(full, o.rect.x0, o.rect.y0, o.scale, o.width_px, o.height_px));
            double best_shifted = 0.0;
            for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
                best_shifted = std::max(
                    best_shifted,
                    test::psnrDb(outer, test::areaDownsample(full, o.rect.x0 + dx * o.scale,
                                                             o.rect.y0 + dy * o.scale, o.scale,
                                                             o.width_px, o.height_px)));
            // Point-sampled at s2, the two-pass outer layer for comparison.
            ImageRgba8 two_pass_outer;
            ASSERT_TRUE(
                renderLayer(*gl, profile, plan, head, eye, LayerKind::kOuter, two_pass_outer));
            const double point_sampled = test::psnrDb(
                two_pass_outer,
                test::areaDownsample(full, o.rect.x0, o.rect.y0, o.scale, o.width_px, o.height_px));
            std::printf(
                "%s eye, grid %dx%d: middle %dx%d: %.3f%% of texels differ by > 1 level, "
                "%.3f%% by > 4, %.3f%% by > 16, PSNR %.1f dB; outer %dx%d at scale %.2f vs area "
                "average %.1f dB (best one-texel shift %.1f dB, two-pass point-sampled "
                "%.1f dB)\n",
                eyeName(eye), g.width_px, g.height_px, middle.width(), middle.height(),
                100.0 * differ_1, 100.0 * differ_4, 100.0 * differ_16, middle_psnr, o.width_px,
                o.height_px, o.scale, aligned, best_shifted, point_sampled);
            // Measured 33.0-34.6 dB aligned, 20.2-20.6 dB shifted, 29.4-29.7 dB point-sampled:
            // the reduction lines up with the outer layer's grid and is the better estimate of
            // the area average than rendering at s2.
            EXPECT_GT(aligned, 30.0);
            EXPECT_GT(aligned, best_shifted + 6.0);
            EXPECT_GT(aligned, point_sampled + 1.0);
        }
    }
}

}  // namespace
}  // namespace qvr
