// Bilinear taps of an RGBA8 image along straight lines in 16.16 fixed point: the inner loop of a
// reprojection that steps a homography linearly between exact points (the shared periphery's
// warp, docs/RUNTIME.md §Shared periphery). A Highway kernel and its scalar twin agree bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>

#include "qvr/core/image.h"

namespace qvr {

// n taps, tap k at texel coordinates (x + k·sx, y + k·sy) / 65536 (texel centres at integers),
// each clamped to the image. Weights are the coordinates' 8 fractional bits below the integer:
// v = (top·(256 − fy) + bottom·fy + 32768) >> 16, top and bottom each (a·(256 − fx) + b·fx).
struct FixedSpan {
    int64_t x = 0, y = 0;
    int64_t sx = 0, sy = 0;
    int n = 0;
};

// Writes the spans' taps one after another from dst (RGBA8, alpha 255). src is not empty.
void bilinearSpans(const ImageRgba8& src, const FixedSpan* spans, size_t count, uint8_t* dst);
// The same, a tap at a time (the reference the vector kernel is tested against).
void bilinearSpansScalar(const ImageRgba8& src, const FixedSpan* spans, size_t count, uint8_t* dst);
// The vector target the kernel dispatches to on this CPU.
const char* bilinearSpanTarget();

}  // namespace qvr
