// The recorder's CPU z-buffer (docs/RECORDING.md): coverage where the projection puts a quad,
// depth, early-z overdraw in draw order, near-plane clipping, the 16-bit depth planes and the
// box halving that makes the coarser layer scales.
#include "qvr/trace/depth_raster.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

namespace qvr {
namespace {

// A quad at depth z (negative, in front of an identity camera) spanning [x0, x1] × [y0, y1].
void addQuad(Scene& s, float x0, float y0, float x1, float y1, float z) {
    SceneBatch b;
    b.first_index = static_cast<uint32_t>(s.indices.size());
    const auto base = static_cast<uint32_t>(s.vertices.size());
    for (const glm::vec3& p :
         {glm::vec3(x0, y0, z), glm::vec3(x1, y0, z), glm::vec3(x1, y1, z), glm::vec3(x0, y1, z)}) {
        SceneVertex v;
        v.position = p;
        s.vertices.push_back(v);
        b.bounds.extend(p);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
        s.indices.push_back(base + i);
    b.index_count = 6;
    s.batches.push_back(b);
}

// 90° square frustum: at depth d the view spans ±d, so a quad of half-width h at depth d covers
// the central h/d of the image.
const glm::mat4 kProjection = glm::perspective(glm::radians(90.0f), 1.0f, 0.05f, 400.0f);
const glm::mat4 kView(1.0f);

int covered(const DepthRaster& r) {
    int n = 0;
    for (int32_t o : r.object)
        n += o >= 0 ? 1 : 0;
    return n;
}

TEST(DepthRaster, CoversTheProjectedQuadAtItsDepth) {
    Scene s;
    addQuad(s, -1, -1, 1, 1, -4);  // covers the middle quarter (h/d = 1/4) of each axis
    DepthRasterizer rasterizer(s, 100.0);
    DepthRaster r;
    rasterizer.rasterize(kView, kProjection, 200, 200, 1, r);
    EXPECT_EQ(r.width, 200);
    // 50 × 50 pixels, give or take the pixel centres on the edges.
    EXPECT_NEAR(covered(r), 2500, 2 * 50 + 1);
    const size_t centre = 100 * 200 + 100;
    EXPECT_NEAR(r.depth_m[centre], 4.0f, 1e-4f);
    EXPECT_EQ(r.depth_m[0], 0.0f);
    EXPECT_EQ(r.object[0], -1);
    EXPECT_EQ(r.shaded[centre], 1);
    // Both triangles survive trivial reject; their objects own every covered pixel.
    uint32_t triangles = 0, pixels = 0;
    for (int id = 0; id < rasterizer.objectCount(); ++id) {
        triangles += r.object_triangles[static_cast<size_t>(id)];
        pixels += r.object_pixels[static_cast<size_t>(id)];
    }
    EXPECT_EQ(triangles, 2u);
    EXPECT_EQ(static_cast<int>(pixels), covered(r));
}

TEST(DepthRaster, GroupsTrianglesIntoObjectsByBatchAndCell) {
    // Triangle centroids of this quad: (1.53, 0.87) and (0.87, 1.53): one 100 m cell, two 1 m
    // cells; a second batch in the same place is a different object.
    Scene s;
    addQuad(s, 0.2f, 0.2f, 2.2f, 2.2f, -4);
    EXPECT_EQ(DepthRasterizer(s, 100.0).objectCount(), 1);
    EXPECT_EQ(DepthRasterizer(s, 1.0).objectCount(), 2);
    addQuad(s, 0.2f, 0.2f, 2.2f, 2.2f, -5);
    const DepthRasterizer two(s, 100.0);
    ASSERT_EQ(two.objectCount(), 2);
    EXPECT_EQ(two.objectBatch(0), 0);
    EXPECT_EQ(two.objectBatch(1), 1);
    EXPECT_NEAR(two.objectBounds(1).min.z, -5.0f, 1e-6f);
    EXPECT_NEAR(distanceToBox(glm::vec3(0, 0, 0), two.objectBounds(0)),
                std::sqrt(0.2 * 0.2 * 2 + 16.0), 1e-5);
}

TEST(DepthRaster, CountsOverdrawInDrawOrderWithAnEarlyDepthTest) {
    // Far quad first, then a near one over its centre: the centre is shaded twice. The reverse
    // order shades it once (the far quad fails the depth test there).
    for (bool far_first : {true, false}) {
        Scene s;
        if (far_first) {
            addQuad(s, -2, -2, 2, 2, -4);
            addQuad(s, -0.5f, -0.5f, 0.5f, 0.5f, -2);
        } else {
            addQuad(s, -0.5f, -0.5f, 0.5f, 0.5f, -2);
            addQuad(s, -2, -2, 2, 2, -4);
        }
        DepthRasterizer rasterizer(s, 100.0);
        DepthRaster r;
        rasterizer.rasterize(kView, kProjection, 100, 100, 1, r);
        const size_t centre = 50 * 100 + 50;
        EXPECT_EQ(r.shaded[centre], far_first ? 2 : 1) << far_first;
        EXPECT_NEAR(r.depth_m[centre], 2.0f, 1e-4f);
        EXPECT_EQ(r.shaded[10 * 100 + 50], 0);  // outside both (the far quad spans ±25 px)
        EXPECT_EQ(r.shaded[30 * 100 + 50], 1);  // the far quad only
    }
}

TEST(DepthRaster, ClipsTrianglesThatCrossTheNearPlane) {
    // A floor running from behind the eye to 10 m ahead, 1 m below: its visible part must cover
    // the lower half of the image with depths from the near plane up, none behind the eye.
    Scene s;
    SceneBatch b;
    for (const glm::vec3& p : {glm::vec3(-20, -1, 5), glm::vec3(20, -1, 5), glm::vec3(20, -1, -10),
                               glm::vec3(-20, -1, -10)}) {
        SceneVertex v;
        v.position = p;
        s.vertices.push_back(v);
        b.bounds.extend(p);
    }
    s.indices = {0, 1, 2, 0, 2, 3};
    b.index_count = 6;
    s.batches.push_back(b);
    DepthRasterizer rasterizer(s, 100.0);
    DepthRaster r;
    rasterizer.rasterize(kView, kProjection, 100, 100, 1, r);
    int lower = 0, upper = 0;
    for (int y = 0; y < 100; ++y) {
        for (int x = 0; x < 100; ++x) {
            const float d = r.depth_m[static_cast<size_t>(y * 100 + x)];
            if (d > 0.0f) {
                (y < 50 ? upper : lower) += 1;
                EXPECT_GE(d, 0.05f - 1e-4f);
                EXPECT_LE(d, 10.0f + 1e-3f);
                // Depth of the floor at this row: 1 m below, so d = 1 / tan(angle below axis).
                const double t = (y + 0.5 - 50.0) / 50.0;
                EXPECT_NEAR(d, 1.0 / t, 1e-3 * (1.0 / t)) << x << "," << y;
            }
        }
    }
    EXPECT_EQ(upper, 0);
    // Rows whose floor lies within 10 m: t > 0.1, i.e. y ≥ 55.
    EXPECT_NEAR(lower, 45 * 100, 100);
}

TEST(DepthRaster, ScaledRasterCoversTheSameRegion) {
    Scene s;
    addQuad(s, -1, -1, 1, 1, -4);
    DepthRasterizer rasterizer(s, 1.0);
    DepthRaster full, half;
    rasterizer.rasterize(kView, kProjection, 200, 200, 1, full);
    rasterizer.rasterize(kView, kProjection, 200, 200, 2, half);
    EXPECT_EQ(half.width, 100);
    EXPECT_NEAR(4.0 * covered(half), covered(full), 4.0 * 2 * 25 + 4);
}

TEST(DepthPlanes, HighAndFoldedLowBytesGiveBackTheQuantisedDepth) {
    DepthRaster r;
    r.width = 257;
    r.height = 1;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.05f, 120.0f);
    for (int i = 0; i < r.width; ++i)
        r.depth_m.push_back(i == 0 ? 0.0f : u(rng));
    ImageRgba8 high, low;
    depthPlanes(r, high, low);
    for (int i = 0; i < r.width; ++i) {
        const int hb = high.at(i, 0, 0);
        int lb = low.at(i, 0, 0);
        if (hb & 1)
            lb = 255 - lb;
        const int d16 = hb * 256 + lb;
        if (i == 0) {
            EXPECT_EQ(d16, 65535);
        } else {
            EXPECT_EQ(d16, std::lround(r.depth_m[static_cast<size_t>(i)] / kDepthStepM)) << i;
        }
    }
    // Folding keeps neighbouring depths neighbouring in the low plane across a high-byte step.
    DepthRaster step;
    step.width = 2;
    step.height = 1;
    step.depth_m = {static_cast<float>(255.0 * kDepthStepM),
                    static_cast<float>(256.0 * kDepthStepM)};
    depthPlanes(step, high, low);
    EXPECT_EQ(high.at(0, 0, 0) + 1, high.at(1, 0, 0));
    EXPECT_LE(std::abs(low.at(0, 0, 0) - low.at(1, 0, 0)), 1);
}

TEST(HalveImage, AveragesBlocksAndKeepsOddEdges) {
    ImageRgba8 in(5, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x)
            for (int c = 0; c < 4; ++c)
                in.at(x, y, c) = static_cast<uint8_t>(10 * x + 50 * y + c);
    ImageRgba8 out;
    halveImage(in, out);
    ASSERT_EQ(out.width(), 3);
    ASSERT_EQ(out.height(), 2);
    EXPECT_EQ(out.at(0, 0, 0), (0 + 10 + 50 + 60 + 2) / 4);
    EXPECT_EQ(out.at(2, 0, 1), 40 + 25 + 1);  // column 4 alone, rows 0–1
    EXPECT_EQ(out.at(2, 1, 0), 40 + 100);     // the corner pixel alone
}

}  // namespace
}  // namespace qvr
