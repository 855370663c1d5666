// Canvas sizing for layer streams whose frames change size with e1 (paper §3.1–3.2); see
// docs/CODEC.md for why padding into a canvas beats an IDR per size change.
#include "qvr/core/canvas_policy.h"

#include <algorithm>
#include <cmath>

#include "qvr/core/check.h"

namespace qvr {

CanvasPolicy::CanvasPolicy(int align_px, double headroom, double shrink_ratio,
                           int shrink_after_frames, int max_side_px)
    : m_align(align_px),
      m_headroom(headroom),
      m_shrink_ratio(shrink_ratio),
      m_shrink_after(shrink_after_frames),
      m_max_side(max_side_px) {
    QVR_CHECK(align_px >= 2 && align_px % 2 == 0);
    QVR_CHECK(headroom >= 0.0 && shrink_ratio >= 0.0 && shrink_ratio <= 1.0);
    QVR_CHECK(max_side_px >= align_px);
}

CanvasSize CanvasPolicy::snug(int width, int height, double headroom) const {
    auto side = [&](int v) {
        const int want = static_cast<int>(std::ceil(v * (1.0 + headroom)));
        const int aligned = (want + m_align - 1) / m_align * m_align;
        const int fits = (v + m_align - 1) / m_align * m_align;  // never below the layer
        return std::max(fits, std::min(aligned, m_max_side / m_align * m_align));
    };
    return {side(width), side(height)};
}

CanvasSize CanvasPolicy::next(int width, int height, bool key_due) {
    QVR_CHECK(width > 0 && height > 0);
    m_changed = false;
    if (width > m_canvas.width || height > m_canvas.height) {
        // Outgrown: jump to the layer plus headroom so the next few larger frames still fit.
        m_canvas = snug(width, height, m_headroom);
        m_small_frames = 0;
        m_changed = true;
        return m_canvas;
    }
    const double covered = static_cast<double>(width) * height /
                           (static_cast<double>(m_canvas.width) * m_canvas.height);
    if (covered >= m_shrink_ratio) {
        m_small_frames = 0;
        return m_canvas;
    }
    // Much smaller for a while (e1 grew and stayed), at a key frame the stream sends anyway. On
    // any frame the shrink was an IDR of its own on all four streams at once, 30 frames after a
    // move up: 6-7 KB, 45-50 ms of a 1.33 Mbit/s link, the run's worst motion-to-photon in each
    // of three qvr runs (2CylinderEngine), for padding that costs a P-frame ~9% (CODEC.md).
    if (++m_small_frames >= m_shrink_after && key_due) {
        m_small_frames = 0;
        const CanvasSize s = snug(width, height, m_headroom);
        if (!(s == m_canvas)) {
            m_canvas = s;
            m_changed = true;
        }
    }
    return m_canvas;
}

}  // namespace qvr
