// PSNR over RGB for the codec's quality checks (paper §3.2).
#include "qvr/codec/image_metrics.h"

#include <cmath>
#include <limits>

namespace qvr {

double meanSquaredErrorRgb(const ImageRgba8& a, const ImageRgba8& b) {
    QVR_CHECK(a.width() == b.width() && a.height() == b.height());
    if (a.empty())
        return 0.0;
    double sum = 0.0;
    for (int y = 0; y < a.height(); ++y) {
        const uint8_t* pa = a.row(y);
        const uint8_t* pb = b.row(y);
        int64_t row_sum = 0;  // exact per row, then double across rows
        for (int x = 0; x < a.width() * 4; x += 4) {
            for (int c = 0; c < 3; ++c) {
                const int d = int{pa[x + c]} - int{pb[x + c]};
                row_sum += d * d;
            }
        }
        sum += static_cast<double>(row_sum);
    }
    return sum / (3.0 * static_cast<double>(a.width()) * a.height());
}

double psnrRgb(const ImageRgba8& a, const ImageRgba8& b) {
    const double mse = meanSquaredErrorRgb(a, b);
    if (mse == 0.0)
        return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(255.0 * 255.0 / mse);
}

}  // namespace qvr
