// The periphery's size as a function of e1, precomputed per HMD profile so that LIWC predicts
// T_remote with a lookup instead of planning every candidate (the hardware would hold the same
// table). Indexed by e1 and by the gaze's distance from the image centre.
#pragma once

#include <vector>

#include "qvr/foveation/layer_plan.h"

namespace qvr {

struct PeripheryShape {
    double fovea_pixels = 0.0;   // per eye, the fovea framebuffer
    double middle_pixels = 0.0;  // per eye
    double outer_pixels = 0.0;   // per eye
    double s1 = 1.0;
    double s2 = 1.0;
};

class RemoteSizeTable {
public:
    static constexpr double kE1StepDeg = 0.5;
    static constexpr double kGazeStepDeg = 5.0;

    explicit RemoteSizeTable(const HmdProfile& profile, double max_e1_deg = 90.0,
                             double max_gaze_deg = 40.0);

    // Bilinear in e1 and in the gaze's eccentricity from the image centre.
    PeripheryShape lookup(const Gaze& gaze, double e1_deg) const;
    // The e1 beyond which the fovea covers the whole field for this gaze (approximate).
    double coverDeg(const Gaze& gaze) const;

private:
    int m_e1_steps;
    int m_gaze_steps;
    std::vector<PeripheryShape> m_cells;  // [gaze][e1]
    std::vector<double> m_cover;          // [gaze]
    EyeGeometry m_geometry;
};

}  // namespace qvr
