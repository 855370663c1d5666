// Precomputed periphery sizes for LIWC's remote-latency prediction.
#include "qvr/controller/remote_size_table.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

namespace qvr {

namespace {

// The table's cells and their extent, as the constructor fills its members.
struct Grid {
    int e1_steps = 0;
    int gaze_steps = 0;
    std::vector<PeripheryShape> cells;  // [gaze][e1]
};

Grid buildGrid(const HmdProfile& profile, double max_e1_deg, double max_gaze_deg) {
    Grid g;
    g.e1_steps = static_cast<int>(std::ceil(max_e1_deg / RemoteSizeTable::kE1StepDeg)) + 1;
    g.gaze_steps = static_cast<int>(std::ceil(max_gaze_deg / RemoteSizeTable::kGazeStepDeg)) + 1;
    const LayerPlanner planner(profile);
    g.cells.resize(static_cast<size_t>(g.e1_steps) * static_cast<size_t>(g.gaze_steps));
    for (int gi = 0; gi < g.gaze_steps; ++gi) {
        // Rows are taken along the diagonal: the average of horizontal and vertical offsets.
        const double r = gi * RemoteSizeTable::kGazeStepDeg / std::sqrt(2.0);
        const Gaze gaze{r, r};
        for (int ei = 0; ei < g.e1_steps; ++ei) {
            const LayerPlan p = planner.plan(gaze, ei * RemoteSizeTable::kE1StepDeg);
            PeripheryShape& c = g.cells[static_cast<size_t>(gi * g.e1_steps + ei)];
            c.fovea_pixels = static_cast<double>(p.fovea_pixels);
            c.middle_pixels = static_cast<double>(p.middle_pixels);
            c.outer_pixels = static_cast<double>(p.outer_pixels);
            c.s1 = p.s1;
            c.s2 = p.s2;
        }
    }
    return g;
}

// One grid per profile and range for the whole process: every run of a policy on the same HMD
// (an evaluation has hundreds) reads the same ~1,600 planned layer layouts, so they are planned
// once. The key is everything LayerPlanner reads of the profile, and the range.
std::shared_ptr<const Grid> sharedGrid(const HmdProfile& profile, double max_e1_deg,
                                       double max_gaze_deg) {
    using Key = std::tuple<int, int, double, double, double, double, double, double, double, double,
                           double, double>;
    const Key key{profile.width_px,
                  profile.height_px,
                  profile.fov_h_deg,
                  profile.fov_v_deg,
                  profile.acuity.omega0_deg,
                  profile.acuity.slope,
                  profile.lens.k1,
                  profile.lens.k2,
                  profile.lens.chroma_red_scale,
                  profile.lens.chroma_blue_scale,
                  max_e1_deg,
                  max_gaze_deg};
    // Bounded: a slope fit makes a new profile per step; past the bound the cache starts over.
    constexpr size_t kMaxGrids = 64;
    static std::mutex mutex;
    static std::map<Key, std::shared_ptr<const Grid>> grids;
    {
        std::lock_guard<std::mutex> lock(mutex);
        if (const auto it = grids.find(key); it != grids.end())
            return it->second;
    }
    // Built outside the lock, so threads asking for other profiles need not wait; two threads
    // building the same grid build equal grids, and the first stored is kept.
    auto grid = std::make_shared<const Grid>(buildGrid(profile, max_e1_deg, max_gaze_deg));
    std::lock_guard<std::mutex> lock(mutex);
    if (grids.size() >= kMaxGrids)
        grids.clear();
    return grids.emplace(key, std::move(grid)).first->second;
}

}  // namespace

RemoteSizeTable::RemoteSizeTable(const HmdProfile& profile, double max_e1_deg, double max_gaze_deg)
    : m_geometry(profile) {
    const std::shared_ptr<const Grid> grid = sharedGrid(profile, max_e1_deg, max_gaze_deg);
    m_e1_steps = grid->e1_steps;
    m_gaze_steps = grid->gaze_steps;
    m_cells = grid->cells;
    m_cover.resize(static_cast<size_t>(m_gaze_steps));
    for (int gi = 0; gi < m_gaze_steps; ++gi) {
        const double r = gi * kGazeStepDeg / std::sqrt(2.0);
        m_cover[static_cast<size_t>(gi)] = m_geometry.coverEccentricityDeg(Gaze{r, r});
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
