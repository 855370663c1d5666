// Pinhole eye-image geometry and the bounding box of a view cone (paper §3.1: each layer is a
// disc of eccentricity around the gaze, rendered into the rectangle that bounds it).
#include "qvr/foveation/eye_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

#include "qvr/core/minimize.h"

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
    // Planning asks for the same gaze hundreds of times in a row (every e2 candidate, every
    // cone bound); remember the last answer per thread.
    struct Memo {
        const EyeGeometry* geometry = nullptr;
        int width = 0, height = 0;
        double fx = 0, fy = 0, gx = 0, gy = 0, cover = 0;
    };
    thread_local Memo memo;
    if (memo.geometry == this && memo.width == m_width && memo.height == m_height &&
        memo.fx == m_fx && memo.fy == m_fy && memo.gx == gaze.x_deg && memo.gy == gaze.y_deg)
        return memo.cover;
    const double cover = computeCoverDeg(gaze);
    memo = {this, m_width, m_height, m_fx, m_fy, gaze.x_deg, gaze.y_deg, cover};
    return cover;
}

double EyeGeometry::computeCoverDeg(const Gaze& gaze) const {
    // Below 90° the sublevel sets of eccentricity on the image plane are convex, so the image
    // is covered exactly when its four corners are. Beyond 90° they are not, and the farthest
    // point can sit inside an edge: search the border then.
    const double w = m_width;
    const double h = m_height;
    double best = std::max({eccentricityDeg(gaze, 0, 0), eccentricityDeg(gaze, w, 0),
                            eccentricityDeg(gaze, 0, h), eccentricityDeg(gaze, w, h)});
    if (best < 89.0)
        return best;
    const std::array<std::array<double, 4>, 4> edges = {
        {{0, 0, w, 0}, {w, 0, w, h}, {w, h, 0, h}, {0, h, 0, 0}}};
    constexpr int kSamples = 64;
    for (const auto& e : edges) {
        auto ecc = [&](double t) {
            return -eccentricityDeg(gaze, e[0] + t * (e[2] - e[0]), e[1] + t * (e[3] - e[1]));
        };
        int best_i = 0;
        double best_v = ecc(0.0);
        for (int i = 1; i <= kSamples; ++i) {
            const double v = ecc(static_cast<double>(i) / kSamples);
            if (v < best_v) {
                best_v = v;
                best_i = i;
            }
        }
        const double lo = std::max(0.0, (best_i - 1.0) / kSamples);
        const double hi = std::min(1.0, (best_i + 1.0) / kSamples);
        best = std::max({best, -best_v, -ecc(goldenSectionMin(ecc, lo, hi, 40, 1e-9))});
    }
    return best;
}

RealRect EyeGeometry::coneBounds(const Gaze& gaze, double radius_deg) const {
    const RealRect full{0.0, 0.0, static_cast<double>(m_width), static_cast<double>(m_height)};
    if (!(radius_deg > 0.0))
        return {};
    const glm::dvec3 g = gazeDirection(gaze);
    const double ce = std::cos(radius_deg / kDegPerRad);
    const double se = std::sin(radius_deg / kDegPerRad);
    // Tangent-plane coordinates of the image corners; inside the cone ⟺ g·d ≥ cos(e)·|d|.
    const double tx0 = -m_cx / m_fx, tx1 = (full.x1 - m_cx) / m_fx;
    const double ty0 = m_cy / m_fy, ty1 = -(full.y1 - m_cy) / m_fy;  // rows grow downwards
    auto insideT = [&](double X, double Y) {
        const glm::dvec3 d(X, Y, -1.0);
        return glm::dot(g, d) >= ce * glm::length(d);
    };
    const bool all_corners =
        insideT(tx0, ty0) && insideT(tx1, ty0) && insideT(tx0, ty1) && insideT(tx1, ty1);
    // Below 90° the covered set is convex, so four corners inside mean the whole image is.
    if (all_corners && radius_deg < 90.0)
        return full;
    if (radius_deg >= coverEccentricityDeg(gaze))
        return full;
    // Orthonormal basis around the gaze.
    const glm::dvec3 helper = std::fabs(g.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, g));
    const glm::dvec3 v = glm::cross(g, u);
    // The footprint of the cone in the image is (cone ∩ image plane) ∩ image. Its bounding box
    // is attained at rim points inside the image, image corners inside the cone, or points
    // where the rim crosses an image edge. Sampling the rim can miss its true extreme between
    // two samples; the inflation below covers that (1 − cos(π/96) ≈ 0.05% of the extent).
    double min_x = 1e300, max_x = -1e300, min_y = 1e300, max_y = -1e300;
    auto add = [&](double X, double Y) {
        min_x = std::min(min_x, X);
        max_x = std::max(max_x, X);
        min_y = std::min(min_y, Y);
        max_y = std::max(max_y, Y);
    };
    constexpr double kEps = 1e-12;
    bool clipped = false;
    for (const auto& cs : rimTable()) {
        const glm::dvec3 d = ce * g + se * (cs[0] * u + cs[1] * v);
        const double depth = -d.z;
        if (depth <= 1e-9) {
            clipped = true;  // the cone reaches the horizon: its footprint leaves the image
            continue;
        }
        const double X = d.x / depth, Y = d.y / depth;
        if (X < tx0 - kEps || X > tx1 + kEps || Y > ty0 + kEps || Y < ty1 - kEps) {
            clipped = true;
            continue;
        }
        add(X, Y);
    }
    if (-g.z > 0.0) {
        const double X = g.x / -g.z, Y = g.y / -g.z;
        if (X >= tx0 && X <= tx1 && Y <= ty0 && Y >= ty1)
            add(X, Y);
    }
    if (clipped) {
        const std::array<std::array<double, 2>, 4> corners = {
            {{tx0, ty0}, {tx1, ty0}, {tx1, ty1}, {tx0, ty1}}};
        const double c2 = ce * ce;
        for (size_t k = 0; k < 4; ++k) {
            const auto& a = corners[k];
            const auto& b = corners[(k + 1) % 4];
            if (insideT(a[0], a[1]))
                add(a[0], a[1]);
            // The edge d(t) = (a + t·(b − a), −1) meets the cone's boundary where
            // (g·d)² = cos²e·|d|² with g·d of the sign of cos e: a quadratic in t.
            const double dx = b[0] - a[0], dy = b[1] - a[1];
            const double A = g.x * a[0] + g.y * a[1] - g.z;  // g·d(0)
            const double B = g.x * dx + g.y * dy;            // d(g·d)/dt
            const double C = a[0] * a[0] + a[1] * a[1] + 1.0;
            const double D = 2.0 * (a[0] * dx + a[1] * dy);
            const double E = dx * dx + dy * dy;
            const double qa = B * B - c2 * E, qb = 2.0 * A * B - c2 * D, qc = A * A - c2 * C;
            double roots[2];
            int n = 0;
            if (std::fabs(qa) < 1e-15) {
                if (std::fabs(qb) > 1e-15)
                    roots[n++] = -qc / qb;
            } else {
                const double disc = qb * qb - 4.0 * qa * qc;
                if (disc >= 0.0) {
                    const double sq = std::sqrt(disc);
                    roots[n++] = (-qb - sq) / (2.0 * qa);
                    roots[n++] = (-qb + sq) / (2.0 * qa);
                }
            }
            for (int i = 0; i < n; ++i) {
                const double t = roots[i];
                if (!(t >= 0.0 && t <= 1.0))
                    continue;
                if ((A + B * t) * ce < 0.0)
                    continue;  // the mirror nappe of the squared cone
                add(a[0] + t * dx, a[1] + t * dy);
            }
        }
    }
    if (min_x > max_x)
        return {};  // the cone misses the image
    const double pad_x = 0.0006 * (max_x - min_x);
    const double pad_y = 0.0006 * (max_y - min_y);
    RealRect r;
    r.x0 = std::clamp(m_cx + m_fx * (min_x - pad_x), 0.0, full.x1);
    r.x1 = std::clamp(m_cx + m_fx * (max_x + pad_x), 0.0, full.x1);
    // Image rows grow downwards while eye-space y grows upwards.
    r.y0 = std::clamp(m_cy - m_fy * (max_y + pad_y), 0.0, full.y1);
    r.y1 = std::clamp(m_cy - m_fy * (min_y - pad_y), 0.0, full.y1);
    if (r.x1 <= r.x0)
        r.x1 = std::min(full.x1, r.x0 + 1e-6);
    if (r.y1 <= r.y0)
        r.y1 = std::min(full.y1, r.y0 + 1e-6);
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
