// PSNR and SSIM over the fovea and the periphery of a display image (the quality measure
// for UCA, paper §4.2). SSIM uses 7×7 box windows kept as running sums, so memory stays O(width).
#include "qvr/compose/quality.h"

#include <algorithm>
#include <array>
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
        q.ssim_windows = ssim_windows;
        const double mse = samples > 0 ? sq_err / static_cast<double>(samples) : 0.0;
        q.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse)
                              : std::numeric_limits<double>::infinity();
        q.ssim = ssim_windows > 0 ? ssim_sum / static_cast<double>(ssim_windows) : 0.0;
        return q;
    }
};

}  // namespace

namespace {

// SSIM of luma over 7×7 windows wholly on labelled pixels (region ≠ 0), added to the window's
// centre pixel's region and to the last accumulator (every region).
void accumulateSsim(const std::vector<float>& ly_img, const std::vector<float>& ly_ref,
                    const std::vector<uint8_t>& region, int width, int height,
                    std::vector<Accum>& acc) {
    const size_t all = acc.size() - 1;
    // Sums over the 7×7 window for x, y, x², y², xy and the count of on-field pixels,
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
                for (Accum* a : {&acc[reg - 1u], &acc[all]}) {
                    a->ssim_sum += ssim;
                    a->ssim_windows += 1;
                }
            }
            for (int k = 0; k < 6; ++k)
                s[k] -= col[k][static_cast<size_t>(x - kHalf)];
        }
        addRow(y - kHalf, -1.0);
    }
}

// One pixel's squared RGB error against its reference, counted in its region (1-based) and in
// the last accumulator, which holds every counted pixel.
void addPixelError(std::vector<Accum>& acc, uint8_t region, const std::array<double, 3>& rgb,
                   const std::array<double, 3>& reference) {
    double e2 = 0.0;
    for (size_t c = 0; c < 3; ++c) {
        const double d = rgb[c] - reference[c];
        e2 += d * d;
    }
    for (Accum* a : {&acc[region - 1u], &acc.back()}) {
        a->sq_err += e2;
        a->samples += 3;
        a->pixels += 1;
    }
}

// PSNR and SSIM per region, a region being what `label` makes of a pixel's eccentricity (deg):
// 1..regions, or 0 to leave it out. The last accumulator holds every counted pixel.
template <typename Label>
std::vector<Accum> measureRegions(const HmdProfile& profile, const Gaze& gaze_deg,
                                  const Pose& render_pose, const Pose& display_pose,
                                  const ImageRgba8& image, const ImageRgbD& truth, int regions,
                                  Label label) {
    const int width = image.width();
    const int height = image.height();
    QVR_CHECK(truth.width() == width && truth.height() == height);
    const EyeWarp warp(profile, render_pose.orientation, display_pose.orientation);
    const glm::dvec3 gaze = glm::normalize(glm::dvec3(std::tan(gaze_deg.x_deg / kDegPerRad),
                                                      std::tan(gaze_deg.y_deg / kDegPerRad), -1.0));
    std::vector<uint8_t> region(static_cast<size_t>(width) * static_cast<size_t>(height));
    std::vector<float> ly_img(region.size()), ly_ref(region.size());
    std::vector<Accum> acc(static_cast<size_t>(regions) + 1);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const size_t i =
                static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
            const WarpSample s = warp.map(x + 0.5, y + 0.5);
            uint8_t reg = kOff;
            if (s.inside) {
                const double c = std::clamp(glm::dot(glm::normalize(s.dir), gaze), -1.0, 1.0);
                reg = static_cast<uint8_t>(label(std::acos(c) * kDegPerRad));
            }
            region[i] = reg;
            const double r = image.at(x, y, 0), g = image.at(x, y, 1), b = image.at(x, y, 2);
            ly_img[i] = static_cast<float>(luma(r, g, b));
            ly_ref[i] =
                static_cast<float>(luma(truth.at(x, y, 0), truth.at(x, y, 1), truth.at(x, y, 2)));
            if (reg == kOff)
                continue;
            addPixelError(acc, reg, {r, g, b},
                          {truth.at(x, y, 0), truth.at(x, y, 1), truth.at(x, y, 2)});
        }
    }
    accumulateSsim(ly_img, ly_ref, region, width, height, acc);
    return acc;
}

}  // namespace

QualityReport measureQuality(const HmdProfile& profile, const LayerPlan& plan,
                             const Pose& render_pose, const Pose& display_pose,
                             const ImageRgba8& image, const ImageRgbD& truth) {
    const std::vector<Accum> acc =
        measureRegions(profile, plan.gaze, render_pose, display_pose, image, truth, 2,
                       [&](double e_deg) { return e_deg <= plan.e1_deg ? kFovea : kPeriphery; });
    QualityReport q;
    q.fovea = acc[0].finish();
    q.periphery = acc[1].finish();
    q.all = acc[2].finish();
    return q;
}

BandQuality measureQualityBands(const HmdProfile& profile, const LayerPlan& plan,
                                const Pose& render_pose, const Pose& display_pose,
                                const ImageRgba8& image, const ImageRgbD& truth,
                                double blend_band_texels, double bin_deg) {
    QVR_CHECK(bin_deg > 0.0);
    // The blend band around each layer border: blend_band_texels of the coarser layer.
    const double w1_deg = blend_band_texels * plan.s1 * profile.pixelAngleDeg();
    const double w2_deg = blend_band_texels * plan.s2 * profile.pixelAngleDeg();
    const bool has_middle = plan.e1_deg < plan.cover_deg;
    const bool has_outer = plan.e2_deg < plan.cover_deg;
    auto band = [&](double e) -> uint8_t {
        if ((has_middle && std::fabs(e - plan.e1_deg) <= w1_deg) ||
            (has_outer && std::fabs(e - plan.e2_deg) <= w2_deg))
            return 2;  // blend band
        if (e < plan.e1_deg || !has_middle)
            return 1;  // fovea
        return e < plan.e2_deg || !has_outer ? 3 : 4;
    };
    const std::vector<Accum> b =
        measureRegions(profile, plan.gaze, render_pose, display_pose, image, truth, 4, band);
    BandQuality q;
    q.fovea = b[0].finish();
    q.blend = b[1].finish();
    q.middle = b[2].finish();
    q.outer = b[3].finish();
    q.all = b[4].finish();
    q.blend_deg = {w1_deg, w2_deg};
    const int bins = static_cast<int>(std::ceil(180.0 / bin_deg));
    const std::vector<Accum> e =
        measureRegions(profile, plan.gaze, render_pose, display_pose, image, truth, bins,
                       [&](double deg) { return std::min(bins, 1 + int(deg / bin_deg)); });
    for (int i = 0; i < bins; ++i) {
        if (e[static_cast<size_t>(i)].pixels == 0)
            continue;
        q.by_eccentricity.push_back({(i + 0.5) * bin_deg, e[static_cast<size_t>(i)].finish()});
    }
    return q;
}

std::vector<RegionQuality> measureLabelledQuality(const ImageRgba8& image,
                                                  const ImageRgba8& reference,
                                                  const std::vector<uint8_t>& labels, int regions) {
    const int width = image.width();
    const int height = image.height();
    QVR_CHECK(reference.width() == width && reference.height() == height);
    QVR_CHECK(labels.size() == static_cast<size_t>(width) * static_cast<size_t>(height));
    QVR_CHECK(regions >= 1 && regions < 256);
    std::vector<float> ly_img(labels.size()), ly_ref(labels.size());
    std::vector<Accum> acc(static_cast<size_t>(regions) + 1);
    for (size_t i = 0; i < labels.size(); ++i) {
        const uint8_t* a = image.data() + 4 * i;
        const uint8_t* b = reference.data() + 4 * i;
        ly_img[i] = static_cast<float>(luma(a[0], a[1], a[2]));
        ly_ref[i] = static_cast<float>(luma(b[0], b[1], b[2]));
        const uint8_t reg = labels[i];
        if (reg == kOff)
            continue;
        QVR_CHECK(reg <= regions);
        addPixelError(acc, reg, {double(a[0]), double(a[1]), double(a[2])},
                      {double(b[0]), double(b[1]), double(b[2])});
    }
    accumulateSsim(ly_img, ly_ref, labels, width, height, acc);
    std::vector<RegionQuality> out;
    for (const Accum& a : acc)
        out.push_back(a.finish());
    return out;
}

}  // namespace qvr
