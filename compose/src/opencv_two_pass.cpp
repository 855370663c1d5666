// The OpenCV two-pass anchor (issue 4): composition with cv::remap + cv::blendLinear into a
// full-resolution eye buffer, then the lens + timewarp map and one more cv::remap.
#include "qvr/compose/opencv_two_pass.h"

#if defined(QVR_COMPOSE_HAVE_OPENCV)
#include <algorithm>
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
    cv::Mat composed, layer_up, blended, map_x, map_y, weight, weight_rest, disp_x, disp_y;
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
        // layer k's rect, with w_k = 1 − t_k the ramp of the border at its outer edge.
        for (int k = slot_count - 1; k >= 0; --k) {
            const int layer = layer_of_slot[k];
            const LayerRect& lr =
                layer == 0 ? rects.fovea : (layer == 1 ? rects.middle : rects.outer);
            const ImageRgba8& li =
                layer == 0 ? images.fovea : (layer == 1 ? images.middle : images.outer);
            const PixelRect r = lr.rect;
            const detail::KernelLayer& kl = p.slots[k];
            s.map_x.create(r.height(), r.width(), CV_32FC1);
            s.map_y.create(r.height(), r.width(), CV_32FC1);
            s.weight.create(r.height(), r.width(), CV_32FC1);
            s.weight_rest.create(r.height(), r.width(), CV_32FC1);
            const bool last = k == slot_count - 1;
            s.arena.execute([&] {
                tbb::parallel_for(
                    tbb::blocked_range<int>(0, r.height(), 16),
                    [&](const tbb::blocked_range<int>& rows) {
                        for (int j = rows.begin(); j < rows.end(); ++j) {
                            float* mx = s.map_x.ptr<float>(j);
                            float* my = s.map_y.ptr<float>(j);
                            float* w = s.weight.ptr<float>(j);
                            float* wr = s.weight_rest.ptr<float>(j);
                            const float py = static_cast<float>(r.y0 + j) + 0.5f;
                            const float yt = static_cast<float>(r.y0 + j) * p.ay + p.by;
                            for (int i = 0; i < r.width(); ++i) {
                                const float px = static_cast<float>(r.x0 + i) + 0.5f;
                                mx[i] = px * kl.inv_scale + kl.offset_x;
                                my[i] = py * kl.inv_scale + kl.offset_y;
                                if (last)
                                    continue;
                                const float xt = static_cast<float>(r.x0 + i) * p.ax + p.bx;
                                const float cos_e = (p.gaze[0] * xt + p.gaze[1] * yt - p.gaze[2]) /
                                                    std::sqrt(xt * xt + yt * yt + 1.0f);
                                const float t = std::clamp(
                                    (p.border_c_hi[k] - cos_e) * p.border_inv[k], 0.0f, 1.0f);
                                w[i] = 1.0f - t;
                                wr[i] = t;
                            }
                        }
                    });
            });
            cv::Mat dst = s.composed(cv::Rect(r.x0, r.y0, r.width(), r.height()));
            if (last) {
                cv::remap(wrap(li), dst, s.map_x, s.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
            } else {
                cv::remap(wrap(li), s.layer_up, s.map_x, s.map_y, cv::INTER_LINEAR,
                          cv::BORDER_REPLICATE);
                cv::blendLinear(s.layer_up, dst, s.weight, s.weight_rest, s.blended);
                s.blended.copyTo(dst);
            }
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
                        float* __restrict mx = s.disp_x.ptr<float>(y);
                        float* __restrict my = s.disp_y.ptr<float>(y);
                        const float yt = static_cast<float>(y) * w.ay + w.by;
                        for (int x = 0; x < width; ++x) {
                            const float xt = static_cast<float>(x) * w.ax + w.bx;
                            const float f =
                                (w.k2 * (xt * xt + yt * yt) + w.k1) * (xt * xt + yt * yt) + 1.0f;
                            const float xd = xt * f, yd = yt * f;
                            const float rx = w.m[0] * xd + w.m[1] * yd - w.m[2];
                            const float ry = w.m[3] * xd + w.m[4] * yd - w.m[5];
                            const float depth = -(w.m[6] * xd + w.m[7] * yd - w.m[8]);
                            const float iz = 1.0f / std::max(depth, 1e-6f);
                            const float px = rx * (w.fx * iz) + w.cx;
                            const float py = ry * (-w.fy * iz) + w.cy;
                            const bool inside = depth > 1e-6f && px >= 0.0f && px <= w.width &&
                                                py >= 0.0f && py <= w.height;
                            mx[x] = inside ? px - 0.5f : -10.0f;
                            my[x] = inside ? py - 0.5f : -10.0f;
                        }
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
