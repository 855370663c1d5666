// The analytic test pattern that judges UCA against the two-pass path (paper §4.2):
// sharp edges, text-like strokes one or two pixels wide, and gradients, defined on the
// full-resolution eye image so that every layer and the ground truth derive from one function.
#pragma once

#include <cstdint>

#include "qvr/compose/uca.h"
#include "qvr/core/image.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr {

using ImageRgbD = Image<double, 3>;

// The pattern's colour (0…255 per channel) at a continuous point of a width × height eye image.
void testPatternAt(double px, double py, int width, int height, double rgb[3]);

// The pattern rendered at full resolution, one sample at each pixel centre.
ImageRgba8 renderTestPattern(int width, int height);

// A layer frame of the pattern for a plan: the fovea cut from the full-resolution render, the
// middle and outer layers rendered at their scales with 4×4 supersampling per texel.
LayerFrame makeTestPatternFrame(const HmdProfile& profile, const LayerPlan& plan,
                                const Pose& render_pose, uint64_t frame_index,
                                const ImageRgba8& full_render);

// Ground truth for one eye: the full-resolution render timewarped and lens-distorted for the
// display pose with double-precision maps and bilinear filtering, black off the rendered image.
ImageRgbD groundTruthWarp(const HmdProfile& profile, const ImageRgba8& full_render,
                          const Pose& render_pose, const Pose& display_pose,
                          bool chromatic_aberration = true);

// The ideal display image of the layers themselves: Eq. 4 evaluated at every display pixel in
// double precision (the same map, slots and blend band as UCA; bilinear per layer; no 8-bit
// rounding). Against it, each path's error is its own filtering and rounding, without the
// detail the foveated layers never held.
ImageRgbD layerReferenceWarp(const HmdProfile& profile, const LayerFrame& frame, int eye,
                             const Pose& display_pose, double blend_band_texels = 2.0,
                             bool chromatic_aberration = true);

}  // namespace qvr
