// Fitting one part's cost (hardware.h PartCost) to timed micro-benchmark samples: what
// `qvr calibrate` does for every part of the runtime (docs/MODEL.md §9).
#pragma once

#include <vector>

#include "qvr/sim/hardware.h"

namespace qvr {

// One timed pass: its time, the pixels it shaded and the triangles it drew; full_frame marks a
// whole frame (local's pass, remote's layer), which gets its own scale rather than weighing on
// the law.
struct CostSample {
    double ms = 0.0;
    double pixels = 0.0;
    double triangles = 0.0;
    bool full_frame = false;
    double fragments = -1.0;  // the fragments the pass shaded (< 0: not counted)
};

struct CostFitOptions {
    bool use_px = true;
    bool use_tri = true;
    // Also fit the power law k·Mpx^p·ktri^q and keep it where its residual is smaller.
    bool allow_power = false;
    // Charge the fragments shaded in place of the pixels (every sample must count them; else
    // the pixels): the linear law base + per Mfrag + per ktri, no power law.
    bool use_frag = false;
};

// Fits the law to the samples that are not whole frames. The linear law: least squares weighted
// by 1/ms² (relative errors count, so a 1 ms fovea weighs as much as a 100 ms one); a negative
// slope is dropped and a negative intercept fixed at 0, the rest refitted each time (a cost
// cannot fall with size, nor be negative for a small pass). With allow_power, also the power
// law by least squares on logs; the law with the smaller RMS relative residual over those
// samples is kept. full_frame_scale is the median of measured / law over the whole-frame
// samples (1 without any). With use_frag and every sample counting its fragments, the linear
// law charges fragments (and triangles) in place of pixels, and frag_per_px is the samples'
// fragments over their pixels. No samples: a zero cost.
PartCost fitPartCost(const std::vector<CostSample>& samples, const CostFitOptions& options);

// RMS of (measured − predicted) / measured over the samples, in percent; whole frames are
// predicted with the cost's full_frame_scale.
double costResidualRmsPct(const std::vector<CostSample>& samples, const PartCost& cost);

// One encoded P-frame of one layer: its scale (display pixels per layer pixel along an axis,
// ≥ 1), its pixels and the bits the encoder spent on it.
struct BitsSample {
    double scale = 1.0;
    double pixels = 0.0;
    double bits = 0.0;
    int frame = -1;  // the motion frame it coded (-1: not one of a motion's frames)
};

// The bits law b·s^γ bits per layer pixel. geometric_b is what least squares on logs alone gives
// b; b / geometric_b is how far the per-frame bits sit above their geometric mean.
struct BitsLaw {
    double bits_per_px_at_1 = 0.0;
    double scale_exponent = 0.0;
    double geometric_b = 0.0;
};

// γ from least squares on logs (the law's shape over scale, clamped to ±4); b such that the
// law, applied to every sample's scale and pixels, spends the samples' bits in total — their
// mean, which is what the model's bytes per frame is compared with. The log fit's own b is the
// geometric mean, below the mean by about half the variance of the log bits (a layer's P-frames
// vary by 20–40% frame to frame: 2–8% low). Samples with no pixels or bits are skipped; fewer
// than two left: a zero law.
BitsLaw fitBitsLaw(const std::vector<BitsSample>& samples);

}  // namespace qvr
