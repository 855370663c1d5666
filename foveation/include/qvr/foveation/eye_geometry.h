// The geometry of one rendered eye image: a pinhole projection with the HMD profile's field of
// view. Maps between pixels, view directions and eccentricity from the gaze, and bounds the
// cone of directions within an eccentricity by a pixel rectangle.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "qvr/foveation/hmd_profile.h"

namespace qvr {

// Where the eye looks, as the horizontal and vertical angles of the gaze point on the eye's
// image plane from the optical axis (right and up positive): the gaze point sits at pixel
// (cx + fx·tan x, cy − fy·tan y). Both eyes use the same gaze angles (vergence at infinity).
struct Gaze {
    double x_deg = 0.0;
    double y_deg = 0.0;
};

// A half-open pixel rectangle [x0, x1) × [y0, y1) in full-resolution eye-image pixels.
struct PixelRect {
    int x0 = 0;
    int y0 = 0;
    int x1 = 0;
    int y1 = 0;

    int width() const { return x1 > x0 ? x1 - x0 : 0; }
    int height() const { return y1 > y0 ? y1 - y0 : 0; }
    int64_t area() const { return static_cast<int64_t>(width()) * height(); }
    bool empty() const { return width() == 0 || height() == 0; }
    bool contains(const PixelRect& o) const {
        return o.empty() || (o.x0 >= x0 && o.y0 >= y0 && o.x1 <= x1 && o.y1 <= y1);
    }
    bool operator==(const PixelRect&) const = default;
};

// The same rectangle with real-valued edges, before rounding outward to whole pixels.
struct RealRect {
    double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    double width() const { return x1 > x0 ? x1 - x0 : 0.0; }
    double height() const { return y1 > y0 ? y1 - y0 : 0.0; }
    double area() const { return width() * height(); }
};

class EyeGeometry {
public:
    explicit EyeGeometry(const HmdProfile& profile);

    int width() const { return m_width; }
    int height() const { return m_height; }
    PixelRect fullRect() const { return {0, 0, m_width, m_height}; }

    // Unit view direction (eye space, −z forward) through the image point (px, py).
    glm::dvec3 directionAt(double px, double py) const;
    glm::dvec3 gazeDirection(const Gaze& gaze) const;
    // Angle in degrees between a pixel's direction and the gaze.
    double eccentricityDeg(const Gaze& gaze, double px, double py) const;
    // The smallest eccentricity that covers the whole image: the farthest corner.
    double coverEccentricityDeg(const Gaze& gaze) const;
    // The bounding rectangle, clipped to the image, of the directions within radius_deg of the
    // gaze. Real-valued; roundOut() turns it into whole pixels.
    RealRect coneBounds(const Gaze& gaze, double radius_deg) const;
    PixelRect roundOut(const RealRect& r) const;

private:
    double computeCoverDeg(const Gaze& gaze) const;

    int m_width;
    int m_height;
    double m_fx;
    double m_fy;
    double m_cx;
    double m_cy;
};

}  // namespace qvr
