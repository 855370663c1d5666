// Precomputed periphery sizes for LIWC's remote-latency prediction.
#include "qvr/controller/remote_size_table.h"

#include <algorithm>
#include <cmath>

namespace qvr {

RemoteSizeTable::RemoteSizeTable(const HmdProfile& profile, double max_e1_deg, double max_gaze_deg)
    : m_e1_steps(static_cast<int>(std::ceil(max_e1_deg / kE1StepDeg)) + 1),
      m_gaze_steps(static_cast<int>(std::ceil(max_gaze_deg / kGazeStepDeg)) + 1),
      m_geometry(profile) {
    const LayerPlanner planner(profile);
    m_cells.resize(static_cast<size_t>(m_e1_steps) * static_cast<size_t>(m_gaze_steps));
    m_cover.resize(static_cast<size_t>(m_gaze_steps));
    for (int gi = 0; gi < m_gaze_steps; ++gi) {
        // Rows are taken along the diagonal: the average of horizontal and vertical offsets.
        const double r = gi * kGazeStepDeg / std::sqrt(2.0);
        const Gaze gaze{r, r};
        m_cover[static_cast<size_t>(gi)] = m_geometry.coverEccentricityDeg(gaze);
        for (int ei = 0; ei < m_e1_steps; ++ei) {
            const LayerPlan p = planner.plan(gaze, ei * kE1StepDeg);
            PeripheryShape& c = m_cells[static_cast<size_t>(gi * m_e1_steps + ei)];
            c.fovea_pixels = static_cast<double>(p.fovea_pixels);
            c.middle_pixels = static_cast<double>(p.middle_pixels);
            c.outer_pixels = static_cast<double>(p.outer_pixels);
            c.s1 = p.s1;
            c.s2 = p.s2;
        }
    }
}

PeripheryShape RemoteSizeTable::lookup(const Gaze& gaze, double e1_deg) const {
    const double gr = std::clamp(std::hypot(gaze.x_deg, gaze.y_deg) / kGazeStepDeg, 0.0,
                                 static_cast<double>(m_gaze_steps - 1));
    const double er = std::clamp(e1_deg / kE1StepDeg, 0.0, static_cast<double>(m_e1_steps - 1));
    const int g0 = std::min(static_cast<int>(gr), m_gaze_steps - 2 < 0 ? 0 : m_gaze_steps - 2);
    const int e0 = std::min(static_cast<int>(er), m_e1_steps - 2);
    const double tg = m_gaze_steps > 1 ? gr - g0 : 0.0;
    const double te = er - e0;
    auto cell = [&](int g, int e) -> const PeripheryShape& {
        return m_cells[static_cast<size_t>(std::min(g, m_gaze_steps - 1) * m_e1_steps + e)];
    };
    auto lerp = [](const PeripheryShape& a, const PeripheryShape& b, double t) {
        PeripheryShape r;
        r.fovea_pixels = a.fovea_pixels + t * (b.fovea_pixels - a.fovea_pixels);
        r.middle_pixels = a.middle_pixels + t * (b.middle_pixels - a.middle_pixels);
        r.outer_pixels = a.outer_pixels + t * (b.outer_pixels - a.outer_pixels);
        r.s1 = a.s1 + t * (b.s1 - a.s1);
        r.s2 = a.s2 + t * (b.s2 - a.s2);
        return r;
    };
    const PeripheryShape lo = lerp(cell(g0, e0), cell(g0, e0 + 1), te);
    const PeripheryShape hi = lerp(cell(g0 + 1, e0), cell(g0 + 1, e0 + 1), te);
    return lerp(lo, hi, tg);
}

double RemoteSizeTable::coverDeg(const Gaze& gaze) const {
    return m_geometry.coverEccentricityDeg(gaze);
}

}  // namespace qvr
