// Image quality of a display image against its ground truth (issue 4's measure of UCA, paper
// §4.2): PSNR and SSIM, separately over the fovea (eccentricity ≤ e1) and the periphery.
#pragma once

#include <cstdint>

#include "qvr/compose/test_pattern.h"
#include "qvr/core/image.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {

struct RegionQuality {
    double psnr_db = 0.0;  // over RGB, peak 255; +inf when identical
    double ssim = 0.0;     // mean SSIM of luma over 7×7 windows wholly inside the region's field
    int64_t pixels = 0;
};

struct QualityReport {
    RegionQuality fovea;
    RegionQuality periphery;
    RegionQuality all;
};

// Regions come from where each display pixel lands in the rendered eye (green channel's map):
// the fovea within e1 of the gaze, the periphery beyond; pixels off the rendered image are not
// counted.
QualityReport measureQuality(const HmdProfile& profile, const LayerPlan& plan,
                             const Pose& render_pose, const Pose& display_pose,
                             const ImageRgba8& image, const ImageRgbD& truth);

}  // namespace qvr
