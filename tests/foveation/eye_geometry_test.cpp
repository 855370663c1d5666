// Eye-image geometry: eccentricity from the gaze, the pixel rectangle that bounds a view cone
// (it must contain every pixel within the radius and be tight), and the covering eccentricity.
#include "qvr/foveation/eye_geometry.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace qvr {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

const std::vector<Gaze>& testGazes() {
    static const std::vector<Gaze> gazes = {{0, 0},   {10, 5},  {-20, 12}, {25, -15},   {-35, -30},
                                            {40, 40}, {-45, 0}, {0, 50},   {3.3, -7.7}, {48, -52}};
    return gazes;
}

const std::vector<double>& testRadii() {
    static const std::vector<double> radii = {0.5, 1,  2.5, 5,  7.5, 10, 15,
                                              20,  30, 40,  55, 70,  85, 89.5};
    return radii;
}

// Pixel position of the gaze point, as documented: (cx + fx·tan x, cy − fy·tan y).
void gazePixel(const HmdProfile& p, const Gaze& g, double& px, double& py) {
    px = 0.5 * p.width_px + p.focalXPx() * std::tan(g.x_deg / kDeg);
    py = 0.5 * p.height_px - p.focalYPx() * std::tan(g.y_deg / kDeg);
}

TEST(EyeGeometry, HasZeroEccentricityWhenPixelIsTheGazePoint) {
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()}) {
        const EyeGeometry geo(p);
        EXPECT_EQ(geo.width(), p.width_px);
        EXPECT_EQ(geo.height(), p.height_px);
        for (const Gaze& g : testGazes()) {
            double px, py;
            gazePixel(p, g, px, py);
            EXPECT_NEAR(geo.eccentricityDeg(g, px, py), 0.0, 1e-5);
        }
    }
}

TEST(EyeGeometry, GivesHalfFieldOfViewWhenAtImageEdgeFromCentre) {
    const HmdProfile p = defaultHmdProfile();
    const EyeGeometry geo(p);
    const Gaze centre{0, 0};
    const double w = p.width_px, h = p.height_px;
    EXPECT_NEAR(geo.eccentricityDeg(centre, 0, h / 2), p.fov_h_deg / 2, 1e-9);
    EXPECT_NEAR(geo.eccentricityDeg(centre, w, h / 2), p.fov_h_deg / 2, 1e-9);
    EXPECT_NEAR(geo.eccentricityDeg(centre, w / 2, 0), p.fov_v_deg / 2, 1e-9);
    EXPECT_NEAR(geo.eccentricityDeg(centre, w / 2, h), p.fov_v_deg / 2, 1e-9);
    // Directions: up in the image (small y) is +y in eye space; the centre looks down −z.
    const glm::dvec3 c = geo.directionAt(w / 2, h / 2);
    EXPECT_NEAR(c.z, -1.0, 1e-12);
    EXPECT_GT(geo.directionAt(w / 2, 0).y, 0.0);
    EXPECT_GT(geo.directionAt(w, h / 2).x, 0.0);
    const glm::dvec3 g = geo.gazeDirection({30, 0});
    EXPECT_NEAR(std::acos(-g.z) * kDeg, 30.0, 1e-9);
    EXPECT_GT(g.x, 0.0);
}

// coverEccentricityDeg is the farthest point of the image: a corner while that is under 90°
// (the sublevel sets are then convex), possibly a point inside an edge beyond.
void expectCoversEveryPixel(const HmdProfile& p, const Gaze& g) {
    const EyeGeometry geo(p);
    const double w = p.width_px, h = p.height_px;
    const double cover = geo.coverEccentricityDeg(g);
    const double corners = std::max({geo.eccentricityDeg(g, 0, 0), geo.eccentricityDeg(g, w, 0),
                                     geo.eccentricityDeg(g, 0, h), geo.eccentricityDeg(g, w, h)});
    // At the corners below 90°; beyond, the farthest point may sit inside an edge.
    if (corners < 89.0)
        EXPECT_NEAR(cover, corners, 1e-9);
    else
        EXPECT_GE(cover, corners - 1e-9);
    double worst = 0.0;
    for (double y = 0; y <= h; y += 8)
        for (double x = 0; x <= w; x += 8)
            worst = std::max(worst, geo.eccentricityDeg(g, x, y));
    EXPECT_LE(worst, cover + 1e-9) << "gaze " << g.x_deg << "," << g.y_deg;
    // The farthest corner is attained, so cover is no larger than needed.
    EXPECT_GE(worst, cover - 0.5);
    if (cover < 90.0) {
        const PixelRect all = geo.roundOut(geo.coneBounds(g, cover));
        EXPECT_EQ(all, geo.fullRect()) << g.x_deg << "," << g.y_deg;
    }
}

TEST(EyeGeometry, CoversEveryPixelWhenRadiusIsCoverEccentricity) {
    int checked = 0;
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()}) {
        for (const Gaze& g : testGazes()) {
            expectCoversEveryPixel(p, g);
            ++checked;
        }
    }
    EXPECT_GE(checked, 8);
}

// Once the farthest point is beyond 90° the maximum of eccentricity over the image is no longer
// at a corner: gaze (-45, 0) on the default profile gives 93.68° at the corners but 94.97° at
// the right edge's midpoint (1920, 1080). (Found by this suite; fixed.)
TEST(EyeGeometry, CoversEveryPixelWhenFarthestPointIsBeyond90) {
    for (const Gaze g : {Gaze{-45, 0}, Gaze{0, 50}, Gaze{48, -52}})
        expectCoversEveryPixel(defaultHmdProfile(), g);
}

// Every point with eccentricity ≤ radius lies inside the real-valued rectangle. The set of such
// points is convex (radius < 90°) and contains the gaze point, so it is enough to check a coarse
// grid and, finely, a line just outside each edge that is not the image border.
TEST(EyeGeometry, ConeBoundsContainEveryPixelWhenWithinRadius) {
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()}) {
        const EyeGeometry geo(p);
        const double w = p.width_px, h = p.height_px;
        for (const Gaze& g : testGazes()) {
            for (double e : testRadii()) {
                const RealRect r = geo.coneBounds(g, e);
                for (double y = 0.5; y < h; y += 12) {
                    for (double x = 0.5; x < w; x += 12) {
                        if (geo.eccentricityDeg(g, x, y) > e)
                            continue;
                        ASSERT_TRUE(x >= r.x0 && x <= r.x1 && y >= r.y0 && y <= r.y1)
                            << "gaze " << g.x_deg << "," << g.y_deg << " e " << e << " pixel " << x
                            << "," << y;
                    }
                }
                constexpr double kOut = 0.01;
                auto outside_ok = [&](double x, double y) {
                    return x < 0 || x > w || y < 0 || y > h || geo.eccentricityDeg(g, x, y) > e;
                };
                for (double y = r.y0 - 1; y <= r.y1 + 1; y += 0.5) {
                    if (r.x0 > 0) {
                        ASSERT_TRUE(outside_ok(r.x0 - kOut, y))
                            << "left edge, gaze " << g.x_deg << "," << g.y_deg << " e " << e;
                    }
                    if (r.x1 < w) {
                        ASSERT_TRUE(outside_ok(r.x1 + kOut, y))
                            << "right edge, gaze " << g.x_deg << "," << g.y_deg << " e " << e;
                    }
                }
                for (double x = r.x0 - 1; x <= r.x1 + 1; x += 0.5) {
                    if (r.y0 > 0) {
                        ASSERT_TRUE(outside_ok(x, r.y0 - kOut))
                            << "top edge, gaze " << g.x_deg << "," << g.y_deg << " e " << e;
                    }
                    if (r.y1 < h) {
                        ASSERT_TRUE(outside_ok(x, r.y1 + kOut))
                            << "bottom edge, gaze " << g.x_deg << "," << g.y_deg << " e " << e;
                    }
                }
                // The rounded rectangle contains the real one and stays in the image.
                const PixelRect pr = geo.roundOut(r);
                EXPECT_LE(pr.x0, r.x0);
                EXPECT_LE(pr.y0, r.y0);
                EXPECT_GE(pr.x1, r.x1);
                EXPECT_GE(pr.y1, r.y1);
                EXPECT_GT(pr.x0, r.x0 - 1.0);
                EXPECT_LT(pr.x1, r.x1 + 1.0);
                EXPECT_TRUE(geo.fullRect().contains(pr));
            }
        }
    }
}

// The rectangle is tight: two pixels inside each edge that is not the image border there is a
// point within the radius (the cone's footprint reaches to within two pixels of the edge).
// Returns how many edges were checked.
int expectTightEdges(const HmdProfile& p, const Gaze& g, double e) {
    constexpr double kInPx = 2.0;
    const EyeGeometry geo(p);
    const double w = p.width_px, h = p.height_px;
    const RealRect r = geo.coneBounds(g, e);
    if (r.width() < 2 * kInPx + 1 || r.height() < 2 * kInPx + 1)
        return 0;
    auto min_along_column = [&](double x) {
        double best = 180.0;
        for (double y = r.y0; y <= r.y1; y += 0.25)
            best = std::min(best, geo.eccentricityDeg(g, x, y));
        return best;
    };
    auto min_along_row = [&](double y) {
        double best = 180.0;
        for (double x = r.x0; x <= r.x1; x += 0.25)
            best = std::min(best, geo.eccentricityDeg(g, x, y));
        return best;
    };
    const std::string where = "gaze " + std::to_string(g.x_deg) + "," + std::to_string(g.y_deg) +
                              " e " + std::to_string(e);
    int edges = 0;
    if (r.x0 > 0) {
        EXPECT_LE(min_along_column(r.x0 + kInPx), e) << "left, " << where;
        ++edges;
    }
    if (r.x1 < w) {
        EXPECT_LE(min_along_column(r.x1 - kInPx), e) << "right, " << where;
        ++edges;
    }
    if (r.y0 > 0) {
        EXPECT_LE(min_along_row(r.y0 + kInPx), e) << "top, " << where;
        ++edges;
    }
    if (r.y1 < h) {
        EXPECT_LE(min_along_row(r.y1 - kInPx), e) << "bottom, " << where;
        ++edges;
    }
    return edges;
}

bool clippedByImage(const HmdProfile& p, const Gaze& g, double e) {
    const RealRect r = EyeGeometry(p).coneBounds(g, e);
    return r.x0 <= 0 || r.y0 <= 0 || r.x1 >= p.width_px || r.y1 >= p.height_px;
}

TEST(EyeGeometry, ConeBoundsAreTightWhenConeLiesInsideImage) {
    int edges = 0;
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()})
        for (const Gaze& g : testGazes())
            for (double e : testRadii())
                if (!clippedByImage(p, g, e))
                    edges += expectTightEdges(p, g, e);
    EXPECT_GE(edges, 100);
}

// When the cone's projection leaves the image, the bounds are those of the footprint inside the
// image, not the clipped bounds of the whole projection (found by this suite; fixed). Default
// profile, gaze (40, 40), e = 40: left edge at x = 665 while no pixel left of x = 820.5 is within
// 40°; gaze (-45, 0), e = 30: top edge at y = 323, footprint starts at y = 411. The extra area
// inflates middle-layer pixels (and the cost e2* is optimised against).
TEST(EyeGeometry, ConeBoundsAreTightWhenConeIsClippedByImage) {
    for (const HmdProfile& p : {defaultHmdProfile(), lowResHmdProfile()})
        for (const Gaze& g : testGazes())
            for (double e : testRadii())
                if (clippedByImage(p, g, e))
                    expectTightEdges(p, g, e);
}

TEST(EyeGeometry, ConeBoundsAreEmptyOrFullWhenRadiusIsExtreme) {
    const EyeGeometry geo(defaultHmdProfile());
    for (const Gaze& g : testGazes()) {
        EXPECT_EQ(geo.coneBounds(g, 0.0).area(), 0.0);
        EXPECT_EQ(geo.coneBounds(g, -3.0).area(), 0.0);
        EXPECT_TRUE(geo.roundOut(geo.coneBounds(g, 0.0)).empty());
        EXPECT_EQ(geo.roundOut(geo.coneBounds(g, geo.coverEccentricityDeg(g))), geo.fullRect());
        EXPECT_EQ(geo.roundOut(geo.coneBounds(g, 179.0)), geo.fullRect());
        // A tiny cone still contains the gaze pixel.
        double px, py;
        gazePixel(defaultHmdProfile(), g, px, py);
        const PixelRect tiny = geo.roundOut(geo.coneBounds(g, 0.01));
        EXPECT_FALSE(tiny.empty());
        EXPECT_LE(tiny.x0, px);
        EXPECT_GE(tiny.x1, px);
        EXPECT_LE(tiny.y0, py);
        EXPECT_GE(tiny.y1, py);
    }
}

TEST(EyeGeometry, ConeBoundsGrowWhenRadiusGrows) {
    const EyeGeometry geo(defaultHmdProfile());
    for (const Gaze& g : testGazes()) {
        RealRect prev = geo.coneBounds(g, 0.1);
        for (double e = 0.2; e < 90.0; e += 0.1) {
            const RealRect r = geo.coneBounds(g, e);
            EXPECT_LE(r.x0, prev.x0 + 1e-9);
            EXPECT_LE(r.y0, prev.y0 + 1e-9);
            EXPECT_GE(r.x1, prev.x1 - 1e-9);
            EXPECT_GE(r.y1, prev.y1 - 1e-9);
            prev = r;
        }
    }
}

TEST(PixelRect, MeasuresAndContainsWhenHalfOpen) {
    const PixelRect a{10, 20, 30, 60};
    EXPECT_EQ(a.width(), 20);
    EXPECT_EQ(a.height(), 40);
    EXPECT_EQ(a.area(), 800);
    EXPECT_FALSE(a.empty());
    EXPECT_TRUE(a.contains({10, 20, 30, 60}));
    EXPECT_TRUE(a.contains({15, 25, 16, 26}));
    EXPECT_FALSE(a.contains({9, 25, 16, 26}));
    EXPECT_FALSE(a.contains({15, 25, 31, 26}));
    EXPECT_TRUE(a.contains({100, 100, 100, 200}));  // empty is contained anywhere
    const PixelRect inverted{30, 20, 10, 60};
    EXPECT_EQ(inverted.width(), 0);
    EXPECT_TRUE(inverted.empty());
    EXPECT_EQ(inverted.area(), 0);
}

}  // namespace
}  // namespace qvr
