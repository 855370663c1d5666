// Image quality metrics for the codec's tests and docs (paper §3.2: the periphery must survive
// the video codec): PSNR over RGB, as the compose part reports it.
#pragma once

#include "qvr/core/image.h"

namespace qvr {

// Mean squared error over the R, G and B channels (alpha ignored); images must match in size.
double meanSquaredErrorRgb(const ImageRgba8& a, const ImageRgba8& b);
// PSNR in dB with peak 255; +infinity for identical images.
double psnrRgb(const ImageRgba8& a, const ImageRgba8& b);

}  // namespace qvr
