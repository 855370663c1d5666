// PSNR and SSIM over the fovea and the periphery of a display image (issue 4's quality measure
// for UCA, paper §4.2). SSIM uses 7×7 box windows kept as running sums, so memory stays O(width).
#include "qvr/compose/quality.h"

#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "qvr/compose/warp.h"

namespace qvr {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr int kHalf = 3;  // 7×7 windows
constexpr int kWindow = (2 * kHalf + 1) * (2 * kHalf + 1);

enum Region : uint8_t { kOff = 0, kFovea = 1, kPeriphery = 2 };

double luma(double r, double g, double b) {
    return 0.299 * r + 0.587 * g + 0.114 * b;
}

struct Accum {
    double sq_err = 0.0;
    int64_t samples = 0;
    double ssim_sum = 0.0;
    int64_t ssim_windows = 0;
    int64_t pixels = 0;

    RegionQuality finish() const {
        RegionQuality q;
        q.pixels = pixels;
        const double mse = samples > 0 ? sq_err / static_cast<double>(samples) : 0.0;
        q.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse)
                              : std::numeric_limits<double>::infinity();
        q.ssim = ssim_windows > 0 ? ssim_sum / static_cast<double>(ssim_windows) : 0.0;
        return q;
    }
};

}  // namespace

QualityReport measureQuality(const HmdProfile& profile, const LayerPlan& plan,
                             const Pose& render_pose, const Pose& display_pose,
                             const ImageRgba8& image, const ImageRgbD& truth) {
    const int width = image.width();
    const int height = image.height();
    QVR_CHECK(truth.width() == width && truth.height() == height);
    const EyeWarp warp(profile, render_pose.orientation, display_pose.orientation);
    const glm::dvec3 gaze = glm::normalize(glm::dvec3(
        std::tan(plan.gaze.x_deg / kDegPerRad), std::tan(plan.gaze.y_deg / kDegPerRad), -1.0));
    const double cos_e1 = std::cos(plan.e1_deg / kDegPerRad);
    std::vector<uint8_t> region(static_cast<size_t>(width) * static_cast<size_t>(height));
    std::vector<float> ly_img(region.size()), ly_ref(region.size());
    Accum acc[3];  // fovea, periphery, all
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const size_t i =
                static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
            const WarpSample s = warp.map(x + 0.5, y + 0.5);
            uint8_t reg = kOff;
            if (s.inside) {
                const double c = glm::dot(glm::normalize(s.dir), gaze);
                reg = c >= cos_e1 ? kFovea : kPeriphery;
            }
            region[i] = reg;
            const double r = image.at(x, y, 0), g = image.at(x, y, 1), b = image.at(x, y, 2);
            ly_img[i] = static_cast<float>(luma(r, g, b));
            ly_ref[i] =
                static_cast<float>(luma(truth.at(x, y, 0), truth.at(x, y, 1), truth.at(x, y, 2)));
            if (reg == kOff)
                continue;
            double e2 = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double d = image.at(x, y, c) - truth.at(x, y, c);
                e2 += d * d;
            }
            for (Accum* a : {&acc[reg - 1], &acc[2]}) {
                a->sq_err += e2;
                a->samples += 3;
                a->pixels += 1;
            }
        }
    }
    // SSIM: sums over the 7×7 window for x, y, x², y², xy and the count of on-field pixels,
    // kept per column over the current 7 rows, then summed across 7 columns.
    constexpr double kC1 = (0.01 * 255.0) * (0.01 * 255.0);
    constexpr double kC2 = (0.03 * 255.0) * (0.03 * 255.0);
    const size_t w = static_cast<size_t>(width);
    std::vector<double> col[6];
    for (auto& c : col)
        c.assign(w, 0.0);
    auto addRow = [&](int y, double sign) {
        const size_t base = static_cast<size_t>(y) * w;
        for (size_t x = 0; x < w; ++x) {
            const double a = ly_img[base + x];
            const double b = ly_ref[base + x];
            col[0][x] += sign * a;
            col[1][x] += sign * b;
            col[2][x] += sign * a * a;
            col[3][x] += sign * b * b;
            col[4][x] += sign * a * b;
            col[5][x] += sign * (region[base + x] != kOff ? 1.0 : 0.0);
        }
    };
    for (int y = 0; y < std::min(2 * kHalf, height); ++y)
        addRow(y, 1.0);
    for (int y = kHalf; y + kHalf < height; ++y) {
        addRow(y + kHalf, 1.0);
        double s[6] = {0, 0, 0, 0, 0, 0};
        for (int x = 0; x < 2 * kHalf && x < width; ++x) {
            for (int k = 0; k < 6; ++k)
                s[k] += col[k][static_cast<size_t>(x)];
        }
        for (int x = kHalf; x + kHalf < width; ++x) {
            for (int k = 0; k < 6; ++k)
                s[k] += col[k][static_cast<size_t>(x + kHalf)];
            const uint8_t reg = region[static_cast<size_t>(y) * w + static_cast<size_t>(x)];
            if (reg != kOff && s[5] > kWindow - 0.5) {
                const double n = kWindow;
                const double mx = s[0] / n, my = s[1] / n;
                const double vx = s[2] / n - mx * mx, vy = s[3] / n - my * my;
                const double cxy = s[4] / n - mx * my;
                const double ssim = ((2 * mx * my + kC1) * (2 * cxy + kC2)) /
                                    ((mx * mx + my * my + kC1) * (vx + vy + kC2));
                for (Accum* a : {&acc[reg - 1], &acc[2]}) {
                    a->ssim_sum += ssim;
                    a->ssim_windows += 1;
                }
            }
            for (int k = 0; k < 6; ++k)
                s[k] -= col[k][static_cast<size_t>(x - kHalf)];
        }
        addRow(y - kHalf, -1.0);
    }
    QualityReport q;
    q.fovea = acc[0].finish();
    q.periphery = acc[1].finish();
    q.all = acc[2].finish();
    return q;
}

}  // namespace qvr
