// The measurement behind `qvr bench uca` (paper §4.2): UCA, the two-pass reference and
// the OpenCV anchor on one frame of the test pattern, timed in the same run, against the memory
// bandwidth floor for UCA's bytes and against the double-precision ground truth.
#pragma once

#include <optional>
#include <string>

#include "qvr/compose/quality.h"
#include "qvr/compose/uca.h"
#include "qvr/core/expected.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/hmd_profile.h"

namespace qvr {

struct UcaBenchOptions {
    HmdProfile profile = defaultHmdProfile();
    double e1_deg = 15.0;
    Gaze gaze{};
    EulerDeg pose_change{2.0, 1.0, 0.5};  // display pose relative to render pose
    int threads = 2;
    int iterations = 21;
    bool opencv = true;   // run the OpenCV anchor when built
    bool quality = true;  // PSNR/SSIM against the ground truth
};

struct UcaBenchResult {
    double uca_ms = 0.0;         // median per frame, both eyes
    double uca_scalar_ms = 0.0;  // the scalar twin, same run
    double two_pass_ms = 0.0;
    std::optional<double> opencv_two_pass_ms;
    double bandwidth_floor_ms = 0.0;  // UCA's bytes at the measured copy bandwidth (median)
    // The fastest run of each, less sensitive than the median to other processes on the cores.
    double uca_min_ms = 0.0;
    double two_pass_min_ms = 0.0;
    std::optional<double> opencv_two_pass_min_ms;
    double bandwidth_floor_min_ms = 0.0;  // at the best copy bandwidth
    double uca_bytes = 0.0;               // layers read + display images written, both eyes
    double copy_gbps = 0.0;               // measured read+write bandwidth of a large copy
    double pose_change_deg = 0.0;
    TileStats tiles;
    QualityReport uca_quality;       // left eye
    QualityReport two_pass_quality;  // left eye
    std::optional<QualityReport> opencv_quality;
    // The same, against the layers' own double-precision Eq. 4 (layerReferenceWarp): each path's
    // filtering error alone.
    QualityReport uca_vs_layers;
    QualityReport two_pass_vs_layers;
    std::optional<QualityReport> opencv_vs_layers;
    int threads = 0;
    std::string simd_target;
};

Expected<UcaBenchResult> runUcaBenchmark(const UcaBenchOptions& options);

}  // namespace qvr
