// The scalar twin of bilinear_span_hwy.cpp (bilinear_span.h).
#include <algorithm>

#include "qvr/compose/bilinear_span.h"
#include "qvr/core/check.h"

namespace qvr {

void bilinearSpansScalar(const ImageRgba8& src, const FixedSpan* spans, size_t count,
                         uint8_t* dst) {
    QVR_CHECK(!src.empty());
    const int w = src.width(), h = src.height();
    const size_t stride = static_cast<size_t>(w) * 4;
    const uint8_t* p = src.data();
    const int64_t max_x = int64_t(w - 1) << 16, max_y = int64_t(h - 1) << 16;
    for (size_t s = 0; s < count; ++s) {
        int64_t x = spans[s].x, y = spans[s].y;
        for (int k = 0; k < spans[s].n; ++k, x += spans[s].sx, y += spans[s].sy, dst += 4) {
            const int64_t cx = std::clamp<int64_t>(x, 0, max_x);
            const int64_t cy = std::clamp<int64_t>(y, 0, max_y);
            const int x0 = int(cx >> 16), y0 = int(cy >> 16);
            const uint32_t fx = uint32_t(cx >> 8) & 255u, fy = uint32_t(cy >> 8) & 255u;
            const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
            const uint8_t* p00 = p + size_t(y0) * stride + size_t(x0) * 4;
            const uint8_t* p10 = p + size_t(y0) * stride + size_t(x1) * 4;
            const uint8_t* p01 = p + size_t(y1) * stride + size_t(x0) * 4;
            const uint8_t* p11 = p + size_t(y1) * stride + size_t(x1) * 4;
            for (int c = 0; c < 3; ++c) {
                const uint32_t top = p00[c] * (256u - fx) + p10[c] * fx;
                const uint32_t bottom = p01[c] * (256u - fx) + p11[c] * fx;
                dst[c] = uint8_t((top * (256u - fy) + bottom * fy + 32768u) >> 16);
            }
            dst[3] = 255;
        }
    }
}

}  // namespace qvr
