// Timewarp of one eye (paper §4.2, Fig. 10): the map from a display pixel to a point of the
// rendered eye image — radial lens pre-distortion, then rotational reprojection from the display
// pose back to the pose the layers were rendered for. docs/UCA.md derives it.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "qvr/foveation/hmd_profile.h"

namespace qvr {

// Where one display point lands in the rendered eye image.
struct WarpSample {
    double px = 0.0;        // rendered-image x, full-resolution pixels (pixel centres at i + 0.5)
    double py = 0.0;        // rendered-image y, rows grow downwards
    glm::dvec3 dir{0.0};    // unnormalised direction in rendered eye space (−z forward)
    bool in_front = false;  // the direction points into the rendered hemisphere
    bool inside = false;    // in front and within the rendered image [0, W] × [0, H]
};

// The double-precision reference of the map every UCA kernel evaluates in float. Display and
// rendered image share the profile's pinhole intrinsics; the lens centre is the image centre.
class EyeWarp {
public:
    EyeWarp(const HmdProfile& profile, const glm::quat& render_orientation,
            const glm::quat& display_orientation);

    // (dx, dy): a point of the display image in pixels; chroma_scale: 1 for green, the lens'
    // red or blue scale for those channels.
    WarpSample map(double dx, double dy, double chroma_scale = 1.0) const;

    // Display eye space → rendered eye space: conj(q_render) · q_display.
    const glm::dmat3& rotation() const { return m_rotation; }
    double fx() const { return m_fx; }
    double fy() const { return m_fy; }
    double cx() const { return m_cx; }
    double cy() const { return m_cy; }
    int width() const { return m_width; }
    int height() const { return m_height; }
    const LensProfile& lens() const { return m_lens; }

private:
    int m_width;
    int m_height;
    double m_fx, m_fy, m_cx, m_cy;
    LensProfile m_lens;
    glm::dmat3 m_rotation;
};

// The lens polynomial on tangent-space radius: a display point at tangent radius r samples the
// undistorted image at r · (1 + k1·r² + k2·r⁴).
inline double lensRadialFactor(const LensProfile& lens, double r2) {
    return 1.0 + r2 * (lens.k1 + lens.k2 * r2);
}

}  // namespace qvr
