// Layer planning (paper §3.1, Eq. 1). e2* is found by a coarse scan followed by a golden-section
// refinement around the best scan point: the cost is smooth between the two ends but not
// guaranteed unimodal once rectangles clip against the image edges, so a pure bracket search
// could stop in the wrong valley.
#include "qvr/foveation/layer_plan.h"

#include <algorithm>
#include <cmath>

#include "qvr/core/minimize.h"

namespace qvr {

namespace {

constexpr double kScanStepDeg = 0.5;

LayerRect makeLayer(const EyeGeometry& geometry, const RealRect& r, double scale) {
    LayerRect layer;
    layer.rect = geometry.roundOut(r);
    layer.scale = scale;
    if (!layer.rect.empty()) {
        layer.width_px = static_cast<int>(std::ceil(layer.rect.width() / scale - 1e-9));
        layer.height_px = static_cast<int>(std::ceil(layer.rect.height() / scale - 1e-9));
    }
    return layer;
}

}  // namespace

double peripheryCost(const HmdProfile& profile, const EyeGeometry& geometry, const Gaze& gaze,
                     double e1_deg, double e2_deg) {
    const double cover = geometry.coverEccentricityDeg(gaze);
    if (e1_deg >= cover)
        return 0.0;
    e2_deg = std::clamp(e2_deg, e1_deg, cover);
    const double s1 = profile.scaleAt(e1_deg);
    const double s2 = profile.scaleAt(e2_deg);
    double middle = 0.0;
    if (e2_deg > e1_deg)
        middle = geometry.coneBounds(gaze, e2_deg).area() / (s1 * s1);
    double outer = 0.0;
    if (e2_deg < cover) {
        outer = static_cast<double>(geometry.width()) * geometry.height() / (s2 * s2);
    }
    return middle + outer;
}

LayerPlanner::LayerPlanner(const HmdProfile& profile) : m_profile(profile), m_geometry(profile) {}

double LayerPlanner::optimalE2Deg(const Gaze& gaze, double e1_deg) const {
    const double cover = m_geometry.coverEccentricityDeg(gaze);
    if (e1_deg >= cover)
        return e1_deg;
    auto cost = [&](double e2) { return peripheryCost(m_profile, m_geometry, gaze, e1_deg, e2); };
    // Scan: both ends exactly, and a grid in between.
    double best_e2 = e1_deg;
    double best_cost = cost(e1_deg);
    auto consider = [&](double e2) {
        const double c = cost(e2);
        if (c < best_cost) {
            best_cost = c;
            best_e2 = e2;
        }
    };
    for (double e2 = e1_deg + kScanStepDeg; e2 < cover; e2 += kScanStepDeg)
        consider(e2);
    consider(cover);
    // Refine inside the scan cell on either side of the best point.
    const double lo = std::max(e1_deg, best_e2 - kScanStepDeg);
    const double hi = std::min(cover, best_e2 + kScanStepDeg);
    consider(goldenSectionMin(cost, lo, hi, 30, 1e-4));
    return best_e2;
}

LayerPlan LayerPlanner::plan(const Gaze& gaze, double e1_deg) const {
    LayerPlan p;
    p.gaze = gaze;
    p.e1_deg = std::isnan(e1_deg) ? 0.0 : std::clamp(e1_deg, 0.0, 180.0);
    p.cover_deg = m_geometry.coverEccentricityDeg(gaze);
    p.full_pixels = static_cast<int64_t>(m_geometry.width()) * m_geometry.height();
    p.s1 = m_profile.scaleAt(p.e1_deg);

    EyeLayers eye;
    const RealRect full{0.0, 0.0, static_cast<double>(m_geometry.width()),
                        static_cast<double>(m_geometry.height())};
    if (p.e1_deg >= p.cover_deg) {
        // The fovea covers everything: a purely local frame.
        p.e2_deg = p.e1_deg;
        p.s2 = p.s1;
        eye.fovea = makeLayer(m_geometry, full, 1.0);
        eye.middle.scale = p.s1;
        eye.outer.scale = p.s2;
    } else {
        p.e2_deg = optimalE2Deg(gaze, p.e1_deg);
        p.s2 = m_profile.scaleAt(p.e2_deg);
        eye.fovea = makeLayer(m_geometry, m_geometry.coneBounds(gaze, p.e1_deg), 1.0);
        if (p.e2_deg > p.e1_deg) {
            eye.middle = makeLayer(m_geometry, m_geometry.coneBounds(gaze, p.e2_deg), p.s1);
        } else {
            eye.middle.scale = p.s1;
        }
        if (p.e2_deg < p.cover_deg) {
            eye.outer = makeLayer(m_geometry, full, p.s2);
        } else {
            eye.outer.scale = p.s2;
        }
    }
    p.eyes = {eye, eye};
    p.fovea_pixels = eye.fovea.pixels();
    p.middle_pixels = eye.middle.pixels();
    p.outer_pixels = eye.outer.pixels();
    p.fovea_fraction = static_cast<double>(p.fovea_pixels) / static_cast<double>(p.full_pixels);
    return p;
}

}  // namespace qvr
