// Image quality of a display image against its ground truth (the measure of UCA, paper
// §4.2): PSNR and SSIM, separately over the fovea (eccentricity ≤ e1) and the periphery.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

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
    int64_t ssim_windows = 0;  // the windows the SSIM is the mean of (0: no SSIM)
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

// The same by eccentricity band of the layer plan — fovea (e < e1), the Eq. 4 blend bands
// (within blend_band_texels of the coarser layer's texels of e1 or e2, both sides), middle,
// outer — and in bins of bin_deg of eccentricity, for error-vs-eccentricity plots. Bins hold
// only pixels on the rendered image. A still-image metric: it does not see temporal artefacts
// (flicker and crawling of the periphery from frame to frame).
struct BandQuality {
    RegionQuality fovea;
    RegionQuality blend;
    RegionQuality middle;
    RegionQuality outer;
    RegionQuality all;
    std::array<double, 2> blend_deg{};  // half-widths of the bands at e1 and e2
    struct Bin {
        double center_deg = 0.0;
        RegionQuality q;
    };
    std::vector<Bin> by_eccentricity;
};
BandQuality measureQualityBands(const HmdProfile& profile, const LayerPlan& plan,
                                const Pose& render_pose, const Pose& display_pose,
                                const ImageRgba8& image, const ImageRgbD& truth,
                                double blend_band_texels = 2.0, double bin_deg = 5.0);

// PSNR and SSIM of `image` against `reference` (same size, no warp) per labelled region:
// labels[y · width + x] in 1..regions names the pixel's region, 0 leaves it out (and out of every
// SSIM window). Returns regions + 1 results, the last over every labelled pixel.
std::vector<RegionQuality> measureLabelledQuality(const ImageRgba8& image,
                                                  const ImageRgba8& reference,
                                                  const std::vector<uint8_t>& labels, int regions);

}  // namespace qvr
