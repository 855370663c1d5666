// Pinhole eye-image geometry and the bounding box of a view cone (paper §3.1: each layer is a
// disc of eccentricity around the gaze, rendered into the rectangle that bounds it).
#include "qvr/foveation/eye_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

namespace qvr {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr int kRimSamples = 96;

// cos/sin of the rim parameter, computed once.
const std::array<std::array<double, 2>, kRimSamples>& rimTable() {
    static const auto table = [] {
        std::array<std::array<double, 2>, kRimSamples> t{};
        for (int i = 0; i < kRimSamples; ++i) {
            const double phi = 2.0 * kPi * i / kRimSamples;
            t[i] = {std::cos(phi), std::sin(phi)};
        }
        return t;
    }();
    return table;
}
}  // namespace

EyeGeometry::EyeGeometry(const HmdProfile& profile)
    : m_width(profile.width_px),
      m_height(profile.height_px),
      m_fx(profile.focalXPx()),
      m_fy(profile.focalYPx()),
      m_cx(0.5 * profile.width_px),
      m_cy(0.5 * profile.height_px) {}

glm::dvec3 EyeGeometry::directionAt(double px, double py) const {
    return glm::normalize(glm::dvec3((px - m_cx) / m_fx, -(py - m_cy) / m_fy, -1.0));
}

glm::dvec3 EyeGeometry::gazeDirection(const Gaze& gaze) const {
    return glm::normalize(
        glm::dvec3(std::tan(gaze.x_deg / kDegPerRad), std::tan(gaze.y_deg / kDegPerRad), -1.0));
}

double EyeGeometry::eccentricityDeg(const Gaze& gaze, double px, double py) const {
    const double c = glm::dot(gazeDirection(gaze), directionAt(px, py));
    return std::acos(std::clamp(c, -1.0, 1.0)) * kDegPerRad;
}

double EyeGeometry::coverEccentricityDeg(const Gaze& gaze) const {
    // The sublevel sets of eccentricity on the image plane are convex (for angles under 90°),
    // so the image is covered exactly when its four corners are.
    const double w = m_width;
    const double h = m_height;
    return std::max({eccentricityDeg(gaze, 0, 0), eccentricityDeg(gaze, w, 0),
                     eccentricityDeg(gaze, 0, h), eccentricityDeg(gaze, w, h)});
}

RealRect EyeGeometry::coneBounds(const Gaze& gaze, double radius_deg) const {
    const RealRect full{0.0, 0.0, static_cast<double>(m_width), static_cast<double>(m_height)};
    if (radius_deg <= 0.0)
        return {};
    if (radius_deg >= 90.0)
        return full;
    const glm::dvec3 g = gazeDirection(gaze);
    // Orthonormal basis around the gaze.
    const glm::dvec3 helper = std::fabs(g.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, g));
    const glm::dvec3 v = glm::cross(g, u);
    const double ce = std::cos(radius_deg / kDegPerRad);
    const double se = std::sin(radius_deg / kDegPerRad);
    // A cone that reaches the image plane's horizon projects to an unbounded region: rim
    // directions that point sideways or backwards are pushed to "infinity" along their own
    // image-plane direction, which the clip below turns into the image edge.
    constexpr double kFar = 1e9;
    double min_x = kFar, max_x = -kFar, min_y = kFar, max_y = -kFar;
    // The bounding box of a cone's projection is attained on its rim, except that a sampled
    // rim can miss the true extreme between two samples; the inflation below covers that
    // (the chord error is 1 − cos(π/96) ≈ 0.05% of the radius).
    for (const auto& cs : rimTable()) {
        const glm::dvec3 d = ce * g + se * (cs[0] * u + cs[1] * v);
        const double depth = -d.z;
        double X, Y;
        if (depth > 1e-6) {
            X = d.x / depth;
            Y = d.y / depth;
        } else {
            X = d.x * kFar;
            Y = d.y * kFar;
        }
        min_x = std::min(min_x, X);
        max_x = std::max(max_x, X);
        min_y = std::min(min_y, Y);
        max_y = std::max(max_y, Y);
    }
    // The gaze point itself lies inside; include it in case the cone is tiny.
    const double gx = g.x / -g.z;
    const double gy = g.y / -g.z;
    const double pad_x = 0.0006 * (max_x - min_x);
    const double pad_y = 0.0006 * (max_y - min_y);
    RealRect r;
    r.x0 = m_cx + m_fx * (std::min(min_x, gx) - pad_x);
    r.x1 = m_cx + m_fx * (std::max(max_x, gx) + pad_x);
    // Image rows grow downwards while eye-space y grows upwards.
    r.y0 = m_cy - m_fy * (std::max(max_y, gy) + pad_y);
    r.y1 = m_cy - m_fy * (std::min(min_y, gy) - pad_y);
    r.x0 = std::clamp(r.x0, 0.0, full.x1);
    r.x1 = std::clamp(r.x1, 0.0, full.x1);
    r.y0 = std::clamp(r.y0, 0.0, full.y1);
    r.y1 = std::clamp(r.y1, 0.0, full.y1);
    return r;
}

PixelRect EyeGeometry::roundOut(const RealRect& r) const {
    if (r.width() <= 0.0 || r.height() <= 0.0)
        return {};
    PixelRect p;
    p.x0 = std::clamp(static_cast<int>(std::floor(r.x0)), 0, m_width);
    p.y0 = std::clamp(static_cast<int>(std::floor(r.y0)), 0, m_height);
    p.x1 = std::clamp(static_cast<int>(std::ceil(r.x1)), 0, m_width);
    p.y1 = std::clamp(static_cast<int>(std::ceil(r.y1)), 0, m_height);
    return p;
}

}  // namespace qvr
