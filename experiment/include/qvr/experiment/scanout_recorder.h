// The display video's recorder (`qvr run --video`), shared by `qvr run` and `qvr calibrate`,
// which times its per-frame copy as a part of the headset (scanout_record_ms, docs/MODEL.md §9).
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "qvr/codec/mp4_writer.h"
#include "qvr/compose/png_io.h"
#include "qvr/compose/warp.h"
#include "qvr/core/image.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/runtime/headset_client.h"

namespace qvr::experiment {

// Keeps what the headset scanned out, both eyes side by side at a quarter of the resolution
// on each axis, in memory; encoded after the run. The recording runs inside the headset's loop
// (on its one core); the qvr design's is kept, and every other design pays the same copy for a
// stand-in that keeps nothing (so the designs pay alike), so it must cost that loop next to
// nothing:
// - every frame's buffer is allocated and touched by reserve(), before the run — on these KVM
//   guests the first touch of fresh memory costs ~25 us a page, and an 8 MB image allocated
//   per frame cost the qvr headset ~45 ms a frame;
// - each output pixel averages a horizontal pair of one source row in four (a quarter of the
//   display's memory is read: ~1 ms a frame; a full 2×2 box at half resolution read all of it,
//   3.6 ms even vectorised, 16 ms as it was written). recordMsPerFrame() reports what it took.
class ScanoutRecorder final : public runtime::DisplaySink {
public:
    static constexpr int kScale = 4;
    // keep = false: a stand-in for the designs that are not recorded, doing the same work per
    // frame into one scratch buffer, so that every design's headset pays the same for the video.
    ScanoutRecorder(const HmdProfile& profile, int max_frames, bool fovea_border, bool keep = true)
        : m_profile(profile),
          m_max_frames(max_frames),
          m_fovea_border(fovea_border),
          m_keep(keep) {}
    // Buffers for the next `frames` scan-outs (at most max_frames in all), off the clock.
    void reserve(int frames) {
        const int w = m_profile.width_px / kScale, h = (m_profile.height_px / kScale) & ~1;
        const int want =
            m_keep ? std::min(frames, m_max_frames - static_cast<int>(m_frames.size())) : 1;
        while (static_cast<int>(m_pool.size()) < want)
            m_pool.emplace_back(2 * w, h);  // zero-filled: every page touched now
    }
    void onScanout(const runtime::FrameTelemetry&, const LayerPlan& plan,
                   const std::array<ImageRgba8, 2>& eyes) override {
        if (static_cast<int>(m_frames.size()) >= m_max_frames || eyes[0].empty() || m_pool.empty())
            return;
        const auto t0 = std::chrono::steady_clock::now();
        ImageRgba8 img = std::move(m_pool.back());
        m_pool.pop_back();
        const int w = std::min(eyes[0].width() / kScale, img.width() / 2);
        const int h = std::min(eyes[0].height() / kScale, img.height());
        // Per byte (p + q) / 2 rounded down, on four channels at once.
        auto avg = [](uint32_t p, uint32_t q) { return (p & q) + (((p ^ q) & 0xFEFEFEFEu) >> 1); };
        for (int e = 0; e < 2; ++e)
            for (int y = 0; y < h; ++y) {
                const uint8_t* src = eyes[e].row(kScale * y + kScale / 2);
                uint8_t* dst = img.row(y) + static_cast<size_t>(e) * w * 4;
                for (int x = 0; x < w; ++x) {
                    uint32_t p, q;
                    std::memcpy(&p, src + 4 * (kScale * x + 1), 4);
                    std::memcpy(&q, src + 4 * (kScale * x + 2), 4);
                    const uint32_t v = avg(p, q);
                    std::memcpy(dst + 4 * x, &v, 4);
                }
            }
        m_record_ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        ++m_recorded;
        if (!m_keep) {
            m_pool.push_back(std::move(img));
            return;
        }
        m_frames.push_back(std::move(img));
        const bool has_fovea = !plan.eyes[0].fovea.empty() && plan.e1_deg < plan.cover_deg;
        m_foveae.push_back({plan.gaze, has_fovea ? plan.e1_deg : -1.0});
    }
    // Time the recording took inside the headset's loop, per recorded frame.
    double recordMsPerFrame() const {
        return m_recorded == 0 ? 0.0 : m_record_ms / static_cast<double>(m_recorded);
    }
    // The e1 circle of the shown frame, through the lens map (display pose = render pose, so
    // it ignores the few tenths of a degree of timewarp): where the fovea layer ends.
    void drawFoveaBorder(ImageRgba8& img, const Gaze& gaze, double e1_deg) const {
        const EyeWarp warp(m_profile, glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0));
        const EyeGeometry geometry(m_profile);
        const double band_deg = 0.75 * kScale * m_profile.pixelAngleDeg();
        const int w = img.width() / 2;
        for (int y = 0; y < img.height(); ++y)
            for (int x = 0; x < w; ++x) {
                const WarpSample s = warp.map(kScale * (x + 0.5), kScale * (y + 0.5));
                if (!s.inside)
                    continue;
                if (std::fabs(geometry.eccentricityDeg(gaze, s.px, s.py) - e1_deg) > band_deg)
                    continue;
                for (int e = 0; e < 2; ++e) {
                    img.at(e * w + x, y, 0) = 255;
                    img.at(e * w + x, y, 1) = 220;
                    img.at(e * w + x, y, 2) = 0;
                }
            }
    }
    // H.264 in MP4 (mp4_writer.h): plays in browsers, so report.html embeds it.
    Status writeMp4(const std::string& path) const {
        if (m_frames.empty())
            return makeError("no displayed frames");
        auto mp4 = Mp4Writer::open(path, m_frames[0].width(), m_frames[0].height(),
                                   static_cast<int>(std::lround(m_profile.refresh_hz)));
        if (!mp4)
            return makeError(mp4.error());
        for (size_t i = 0; i < m_frames.size(); ++i) {
            ImageRgba8 f = m_frames[i];
            if (m_fovea_border && m_foveae[i].e1_deg > 0)
                drawFoveaBorder(f, m_foveae[i].gaze, m_foveae[i].e1_deg);
            if (auto st = (*mp4)->write(f); !st)
                return st;
        }
        return (*mp4)->finish();
    }
    size_t frames() const { return m_frames.size(); }
    // One displayed frame as PNG (with the fovea edge when drawn in the video), for a look
    // without a video player.
    Status writePngFrame(size_t i, const std::string& path) const {
        if (i >= m_frames.size())
            return makeError("no displayed frame " + std::to_string(i));
        ImageRgba8 f = m_frames[i];
        if (m_fovea_border && m_foveae[i].e1_deg > 0)
            drawFoveaBorder(f, m_foveae[i].gaze, m_foveae[i].e1_deg);
        return writePng(path, f);
    }

private:
    struct Fovea {
        Gaze gaze;
        double e1_deg = -1.0;
    };
    HmdProfile m_profile;
    int m_max_frames;
    bool m_fovea_border;
    std::vector<ImageRgba8> m_frames;
    std::vector<ImageRgba8> m_pool;  // reserved, not yet used
    std::vector<Fovea> m_foveae;
    bool m_keep;
    double m_record_ms = 0.0;
    int m_recorded = 0;
};

}  // namespace qvr::experiment
