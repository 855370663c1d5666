// The layer plan of one frame (paper §3.1, Eq. 1): the fovea disc of radius e1 rendered locally
// at full resolution; the middle layer, a disc of radius e2* sampled at s1 = ω(e1)/ω*; the outer
// layer, the whole field sampled at s2 = ω(e2*)/ω*; e2* minimises the periphery's pixel count.
#pragma once

#include <array>
#include <cstdint>

#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/hmd_profile.h"

namespace qvr {

// One layer of one eye: the region of the full-resolution eye image it covers and the size of
// its own framebuffer at its sampling scale.
struct LayerRect {
    PixelRect rect;      // in full-resolution pixels, clipped to the image
    double scale = 1.0;  // linear down-sampling factor, ≥ 1
    int width_px = 0;    // framebuffer size: ceil(rect / scale)
    int height_px = 0;

    int64_t pixels() const { return static_cast<int64_t>(width_px) * height_px; }
    bool empty() const { return pixels() == 0; }
};

struct EyeLayers {
    LayerRect fovea;
    LayerRect middle;
    LayerRect outer;
};

struct LayerPlan {
    Gaze gaze;
    double e1_deg = 0.0;
    double e2_deg = 0.0;
    double s1 = 1.0;
    double s2 = 1.0;
    double cover_deg = 0.0;         // the eccentricity that covers the whole field from this gaze
    std::array<EyeLayers, 2> eyes;  // left, right

    // Per eye (both eyes share one gaze, so their counts are equal).
    int64_t fovea_pixels = 0;
    int64_t middle_pixels = 0;
    int64_t outer_pixels = 0;
    int64_t full_pixels = 0;
    double fovea_fraction = 0.0;  // fovea framebuffer / full frame

    int64_t remotePixels() const { return middle_pixels + outer_pixels; }
    bool hasRemote() const { return remotePixels() > 0; }
};

// The quantity Eq. 1 minimises over e2, per eye, with real-valued rectangle edges so that the
// optimum is not an artefact of rounding: P_middle(e2) + P_outer(e2). A middle layer of zero
// width (e2 = e1) costs nothing; an outer layer is not needed once the middle disc covers the
// whole field.
double peripheryCost(const HmdProfile& profile, const EyeGeometry& geometry, const Gaze& gaze,
                     double e1_deg, double e2_deg);

class LayerPlanner {
public:
    explicit LayerPlanner(const HmdProfile& profile);

    const HmdProfile& profile() const { return m_profile; }
    const EyeGeometry& geometry() const { return m_geometry; }

    // e1 is clamped to [0, 180]. An e1 that covers the whole field leaves no remote layer.
    LayerPlan plan(const Gaze& gaze, double e1_deg) const;
    // e2* alone (the search of plan()).
    double optimalE2Deg(const Gaze& gaze, double e1_deg) const;

private:
    HmdProfile m_profile;
    EyeGeometry m_geometry;
};

}  // namespace qvr
