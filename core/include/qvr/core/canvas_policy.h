// How a layer stream's coded canvas follows a layer whose size changes every frame as e1 moves
// (paper §3.1–3.2): grow with headroom when the layer outgrows it, shrink only after the layer
// has stayed much smaller for a while and on a frame that is a key frame anyway, so a canvas
// change costs an IDR only when the layer outgrew it.
#pragma once

namespace qvr {

struct CanvasSize {
    int width = 0;
    int height = 0;
    bool operator==(const CanvasSize&) const = default;
};

class CanvasPolicy {
public:
    CanvasPolicy(int align_px, double headroom, double shrink_ratio, int shrink_after_frames,
                 int max_side_px);
    // The canvas for the next frame of a width×height layer; changed() tells whether it moved.
    // key_due: the stream codes this frame as an IDR whatever its canvas (its periodic key frame,
    // a requested one), the only frame a shrink may take.
    CanvasSize next(int width, int height, bool key_due);
    bool changed() const { return m_changed; }
    CanvasSize current() const { return m_canvas; }
    // The canvas a stream that starts at a width×height layer gets: the layer plus headroom,
    // aligned — what a steady layer codes into.
    CanvasSize snugFor(int width, int height) const { return snug(width, height, m_headroom); }

private:
    CanvasSize snug(int width, int height, double headroom) const;

    int m_align;
    double m_headroom;
    double m_shrink_ratio;
    int m_shrink_after;
    int m_max_side;
    CanvasSize m_canvas;
    int m_small_frames = 0;
    bool m_changed = false;
};

}  // namespace qvr
