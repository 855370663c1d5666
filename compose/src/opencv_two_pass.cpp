// The OpenCV two-pass anchor: composition with cv::remap + cv::blendLinear into a
// full-resolution eye buffer, then the lens + timewarp map and one more cv::remap.
#include "qvr/compose/opencv_two_pass.h"

#if defined(QVR_COMPOSE_HAVE_OPENCV)
#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "uca_kernel.h"
#endif

namespace qvr {

#if !defined(QVR_COMPOSE_HAVE_OPENCV)
bool openCvAnchorBuilt() {
    return false;
}
#else
bool openCvAnchorBuilt() {
    return true;
}

struct OpenCvTwoPass::Scratch {
    tbb::task_arena arena;
    // One set per slot so that steady-state frames reallocate nothing.
    cv::Mat composed, disp_x, disp_y;
    std::array<cv::Mat, 3> layer_up, blended, weight, weight_rest;
    explicit Scratch(int threads) : arena(threads > 0 ? threads : tbb::task_arena::automatic) {}
};

OpenCvTwoPass::OpenCvTwoPass(const HmdProfile& profile, ComposeOptions options)
    : m_profile(profile),
      m_options(options),
      m_scratch(std::make_unique<Scratch>(options.threads)) {
    if (options.threads > 0)
        cv::setNumThreads(options.threads);
}

OpenCvTwoPass::~OpenCvTwoPass() = default;

namespace {

// One row of the display maps: lens + timewarp in float, branch-free so the compiler
// vectorises it (what a careful OpenCV user would write).
void displayMapRow(const detail::KernelParams& w, int y, int width, float* __restrict mx,
                   float* __restrict my) {
    const float ax = w.ax, bx = w.bx, k1 = w.k1, k2 = w.k2;
    const float m0 = w.m[0], m1 = w.m[1], m2 = w.m[2], m3 = w.m[3], m4 = w.m[4], m5 = w.m[5];
    const float m6 = w.m[6], m7 = w.m[7], m8 = w.m[8];
    const float fx = w.fx, fy = w.fy, cx = w.cx, cy = w.cy, wmax = w.width, hmax = w.height;
    const float yt = static_cast<float>(y) * w.ay + w.by;
    for (int x = 0; x < width; ++x) {
        const float xt = static_cast<float>(x) * ax + bx;
        const float r2 = xt * xt + yt * yt;
        const float f = (k2 * r2 + k1) * r2 + 1.0f;
        const float xd = xt * f, yd = yt * f;
        const float rx = m0 * xd + m1 * yd - m2;
        const float ry = m3 * xd + m4 * yd - m5;
        const float depth = -(m6 * xd + m7 * yd - m8);
        const float iz = 1.0f / (depth > 1e-6f ? depth : 1e-6f);
        const float px = rx * (fx * iz) + cx;
        const float py = ry * (-fy * iz) + cy;
        const bool inside =
            (depth > 1e-6f) & (px >= 0.0f) & (px <= wmax) & (py >= 0.0f) & (py <= hmax);
        mx[x] = inside ? px - 0.5f : -10.0f;
        my[x] = inside ? py - 0.5f : -10.0f;
    }
}

cv::Mat wrap(const ImageRgba8& image) {
    return cv::Mat(image.height(), image.width(), CV_8UC4, const_cast<uint8_t*>(image.data()));
}

}  // namespace

Status OpenCvTwoPass::run(const LayerFrame& frame, const Pose& display_pose,
                          std::array<ImageRgba8, 2>& out) {
    if (Status st = validateFrame(m_profile, frame); !st)
        return st;
    Scratch& s = *m_scratch;
    const int width = m_profile.width_px;
    const int height = m_profile.height_px;
    for (int eye = 0; eye < 2; ++eye) {
        const detail::KernelParams p =
            detail::composeParams(m_profile, frame, eye, m_options.blend_band_texels);
        int layer_of_slot[3];
        int slot_count = 0;
        detail::slotLayers(frame.plan, eye, layer_of_slot, slot_count);
        const EyeLayers& rects = frame.plan.eyes[static_cast<size_t>(eye)];
        const EyeLayerImages& images = frame.eyes[static_cast<size_t>(eye)];
        s.composed.create(height, width, CV_8UC4);
        // Pass 1, from the outermost layer inwards: C_k = w_k·L_k + (1 − w_k)·C_{k+1} over
        // layer k's rect, with w_k = 1 − t_k the ramp of the border at its outer edge. A layer
        // is an axis-aligned scale of its rect, so cv::warpAffine resamples it without maps.
        for (int k = slot_count - 1; k >= 0; --k) {
            const int layer = layer_of_slot[k];
            const LayerRect& lr =
                layer == 0 ? rects.fovea : (layer == 1 ? rects.middle : rects.outer);
            const ImageRgba8& li =
                layer == 0 ? images.fovea : (layer == 1 ? images.middle : images.outer);
            const PixelRect r = lr.rect;
            const detail::KernelLayer& kl = p.slots[k];
            // Destination pixel (i, j) of the rect is the texel coordinate
            // ((x0 + i + ½)/s + offset_x, (y0 + j + ½)/s + offset_y).
            const cv::Matx23d to_texel(kl.inv_scale, 0.0, (r.x0 + 0.5) * kl.inv_scale + kl.offset_x,
                                       0.0, kl.inv_scale,
                                       (r.y0 + 0.5) * kl.inv_scale + kl.offset_y);
            cv::Mat dst = s.composed(cv::Rect(r.x0, r.y0, r.width(), r.height()));
            const bool last = k == slot_count - 1;
            cv::Mat& up = last ? dst : s.layer_up[k];
            cv::warpAffine(wrap(li), up, to_texel, cv::Size(r.width(), r.height()),
                           cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
            if (last)
                continue;
            s.weight[k].create(r.height(), r.width(), CV_32FC1);
            s.weight_rest[k].create(r.height(), r.width(), CV_32FC1);
            s.arena.execute([&] {
                tbb::parallel_for(
                    tbb::blocked_range<int>(0, r.height(), 16),
                    [&](const tbb::blocked_range<int>& rows) {
                        for (int j = rows.begin(); j < rows.end(); ++j) {
                            float* __restrict w = s.weight[k].ptr<float>(j);
                            float* __restrict wr = s.weight_rest[k].ptr<float>(j);
                            const float yt = static_cast<float>(r.y0 + j) * p.ay + p.by;
                            for (int i = 0; i < r.width(); ++i) {
                                const float xt = static_cast<float>(r.x0 + i) * p.ax + p.bx;
                                const float cos_e = (p.gaze[0] * xt + p.gaze[1] * yt - p.gaze[2]) /
                                                    std::sqrt(xt * xt + yt * yt + 1.0f);
                                const float t = std::min(
                                    std::max((p.border_c_hi[k] - cos_e) * p.border_inv[k], 0.0f),
                                    1.0f);
                                w[i] = 1.0f - t;
                                wr[i] = t;
                            }
                        }
                    });
            });
            cv::blendLinear(up, dst, s.weight[k], s.weight_rest[k], s.blended[k]);
            s.blended[k].copyTo(dst);
        }
        // Pass 2: lens + timewarp maps for this display pose (float, the loop vectorises),
        // then remap the eye buffer.
        s.disp_x.create(height, width, CV_32FC1);
        s.disp_y.create(height, width, CV_32FC1);
        const detail::KernelParams w =
            detail::timewarpParams(m_profile, frame.render_pose, display_pose, frame.plan.gaze);
        s.arena.execute([&] {
            tbb::parallel_for(
                tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& rows) {
                    for (int y = rows.begin(); y < rows.end(); ++y) {
                        displayMapRow(w, y, width, s.disp_x.ptr<float>(y), s.disp_y.ptr<float>(y));
                    }
                });
        });
        ImageRgba8& o = out[static_cast<size_t>(eye)];
        if (o.width() != width || o.height() != height)
            o.resize(width, height);
        cv::Mat dst = wrap(o);
        cv::remap(s.composed, dst, s.disp_x, s.disp_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                  cv::Scalar(0, 0, 0, 255));
    }
    return Status::success();
}
#endif

}  // namespace qvr
