// Shared helpers of the render tests: a small HMD profile, the GL renderer or a clear skip, and
// image comparisons (centroids, PSNR, area down-sampling onto a layer's texel grid).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include "qvr/core/image.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/gl_renderer.h"

namespace qvr::test {

// 320×360 per eye keeps llvmpipe fast; the coarse acuity model gives the middle and outer
// layers scales well above 1 at this resolution, as the full-size display does at its own.
inline HmdProfile smallProfile() {
    HmdProfile p;
    p.name = "test-320x360";
    p.width_px = 320;
    p.height_px = 360;
    p.fov_h_deg = 100.0;
    p.fov_v_deg = 110.0;
    p.acuity.omega0_deg = 0.2;
    p.acuity.slope = 0.06;
    return p;
}

// Mean absolute RGB difference of two images of one size, in 8-bit levels.
inline double meanAbsDiff(const ImageRgba8& a, const ImageRgba8& b) {
    double sum = 0.0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            for (int c = 0; c < 3; ++c)
                sum += std::abs(int(a.at(x, y, c)) - int(b.at(x, y, c)));
    return sum / (3.0 * a.width() * a.height());
}

// One GL renderer for the whole test program (context creation costs ~50 ms on llvmpipe).
// Skips only when EGL itself cannot give an OpenGL 4.5 context; QVR_REQUIRE_GL=1 makes that a
// failure, for machines where a driver is known to be present.
inline GlRenderer* sharedGlRenderer(std::string* skip_reason) {
    static std::string error;
    static std::unique_ptr<GlRenderer> renderer = [] {
        auto r = GlRenderer::create();
        if (!r) {
            error = r.error();
            return std::unique_ptr<GlRenderer>();
        }
        return std::move(r).value();
    }();
    if (!renderer)
        *skip_reason = error;
    return renderer.get();
}

#define QVR_GL_RENDERER_OR_SKIP(var)                                                    \
    std::string qvr_skip_reason;                                                        \
    GlRenderer* var = ::qvr::test::sharedGlRenderer(&qvr_skip_reason);                  \
    if (var == nullptr) {                                                               \
        const char* require = std::getenv("QVR_REQUIRE_GL");                            \
        if (qvr_skip_reason.rfind("EGL: ", 0) != 0 || (require && require[0] == '1'))   \
            FAIL() << "GL renderer: " << qvr_skip_reason;                               \
        GTEST_SKIP() << "no headless OpenGL 4.5 through EGL here: " << qvr_skip_reason; \
    }

// The centroid, in pixel coordinates (pixel centres at +0.5), of the pixels a predicate picks.
struct Centroid {
    double x = 0.0;
    double y = 0.0;
    int count = 0;
};

inline Centroid centroidOf(const ImageRgba8& img, const std::function<bool(const uint8_t*)>& pick) {
    Centroid c;
    for (int y = 0; y < img.height(); ++y) {
        for (int x = 0; x < img.width(); ++x) {
            if (pick(&img.row(y)[static_cast<size_t>(x) * 4])) {
                c.x += x + 0.5;
                c.y += y + 0.5;
                ++c.count;
            }
        }
    }
    if (c.count > 0) {
        c.x /= c.count;
        c.y /= c.count;
    }
    return c;
}

// PSNR over RGB of two images of one size; +inf when equal.
inline double psnrDb(const ImageRgba8& a, const ImageRgba8& b) {
    EXPECT_EQ(a.width(), b.width());
    EXPECT_EQ(a.height(), b.height());
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < a.height(); ++y) {
        for (int x = 0; x < a.width(); ++x) {
            for (int c = 0; c < 3; ++c) {
                const double d = static_cast<double>(a.at(x, y, c)) - b.at(x, y, c);
                sum += d * d;
                ++n;
            }
        }
    }
    if (n == 0 || sum == 0.0)
        return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(255.0 * 255.0 / (sum / static_cast<double>(n)));
}

// The full frame averaged over each texel of a layer grid: texel (i, j) covers full pixels
// [x0 + i·s, x0 + (i+1)·s) × [y0 + j·s, y0 + (j+1)·s), weighted by overlap, clipped to the
// frame. This is what an ideal renderer at scale s would produce.
inline ImageRgba8 areaDownsample(const ImageRgba8& full, double x0, double y0, double scale,
                                 int width, int height) {
    ImageRgba8 out(width, height);
    for (int j = 0; j < height; ++j) {
        for (int i = 0; i < width; ++i) {
            const double fx0 = x0 + i * scale, fx1 = fx0 + scale;
            const double fy0 = y0 + j * scale, fy1 = fy0 + scale;
            double acc[3] = {0, 0, 0};
            double wsum = 0.0;
            for (int y = std::max(0, static_cast<int>(std::floor(fy0)));
                 y < std::min(full.height(), static_cast<int>(std::ceil(fy1))); ++y) {
                const double wy = std::min<double>(y + 1, fy1) - std::max<double>(y, fy0);
                for (int x = std::max(0, static_cast<int>(std::floor(fx0)));
                     x < std::min(full.width(), static_cast<int>(std::ceil(fx1))); ++x) {
                    const double w = wy * (std::min<double>(x + 1, fx1) - std::max<double>(x, fx0));
                    if (w <= 0.0)
                        continue;
                    for (int c = 0; c < 3; ++c)
                        acc[c] += w * full.at(x, y, c);
                    wsum += w;
                }
            }
            for (int c = 0; c < 3; ++c)
                out.at(i, j, c) = static_cast<uint8_t>(wsum > 0 ? std::lround(acc[c] / wsum) : 0);
            out.at(i, j, 3) = 255;
        }
    }
    return out;
}

// A w×h window of an image starting at (x0, y0); pixels outside it are black.
inline ImageRgba8 crop(const ImageRgba8& img, int x0, int y0, int w, int h) {
    ImageRgba8 out(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const int sx = x0 + x, sy = y0 + y;
            if (sx < 0 || sy < 0 || sx >= img.width() || sy >= img.height())
                continue;
            for (int c = 0; c < 4; ++c)
                out.at(x, y, c) = img.at(sx, sy, c);
        }
    }
    return out;
}

}  // namespace qvr::test
