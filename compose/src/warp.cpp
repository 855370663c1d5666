// The timewarp map of one eye in double precision (paper §4.2): lens pre-distortion on the
// display side, then the rotation from display to render pose, then the render projection.
#include "qvr/compose/warp.h"

#include <glm/gtc/quaternion.hpp>

namespace qvr {

EyeWarp::EyeWarp(const HmdProfile& profile, const glm::quat& render_orientation,
                 const glm::quat& display_orientation)
    : m_width(profile.width_px),
      m_height(profile.height_px),
      m_fx(profile.focalXPx()),
      m_fy(profile.focalYPx()),
      m_cx(0.5 * profile.width_px),
      m_cy(0.5 * profile.height_px),
      m_lens(profile.lens) {
    // A display-space direction d is the world direction q_display·d, which the rendered eye
    // saw as conj(q_render)·q_display·d.
    const glm::dquat qr(render_orientation);
    const glm::dquat qd(display_orientation);
    m_rotation = glm::mat3_cast(glm::normalize(glm::conjugate(qr) * qd));
}

WarpSample EyeWarp::map(double dx, double dy, double chroma_scale) const {
    const double xt = (dx - m_cx) / m_fx;
    const double yt = -(dy - m_cy) / m_fy;
    const double f = lensRadialFactor(m_lens, xt * xt + yt * yt) * chroma_scale;
    const glm::dvec3 d(xt * f, yt * f, -1.0);
    WarpSample s;
    s.dir = m_rotation * d;
    const double depth = -s.dir.z;
    s.in_front = depth > 1e-9;
    if (s.in_front) {
        s.px = m_cx + m_fx * s.dir.x / depth;
        s.py = m_cy - m_fy * s.dir.y / depth;
        s.inside = s.px >= 0.0 && s.px <= m_width && s.py >= 0.0 && s.py <= m_height;
    }
    return s;
}

}  // namespace qvr
