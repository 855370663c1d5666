// The head-mounted display a plan is made for (paper §3.1, §5): per-eye resolution, field of
// view, refresh rate, lens distortion, and the MAR acuity model ω(e) = m·e + ω0 of Eq. 1.
#pragma once

#include <string>
#include <string_view>

#include "qvr/core/expected.h"

namespace qvr {

// Minimum angle of resolution grows linearly with eccentricity (Guenter et al., "Foveated 3D
// Graphics", SIGGRAPH Asia 2012): ω(e) = m·e + ω0, in degrees per pixel.
struct AcuityModel {
    double omega0_deg = 1.0 / 48.0;  // foveal MAR
    double slope = 0.0275;           // m, degrees of MAR per degree of eccentricity

    double marDeg(double eccentricity_deg) const { return slope * eccentricity_deg + omega0_deg; }
};

// Radial lens distortion as HMD runtimes pre-distort for it: a point at tangent-space radius r
// from the lens centre is sampled from r·(1 + k1·r² + k2·r⁴). Chromatic aberration scales the
// red and blue radii relative to green.
struct LensProfile {
    double k1 = 0.22;
    double k2 = 0.24;
    double chroma_red_scale = 1.0;
    double chroma_blue_scale = 1.0;
};

struct HmdProfile {
    std::string name = "default";
    int width_px = 1920;   // per eye
    int height_px = 2160;  // per eye
    double fov_h_deg = 100.0;
    double fov_v_deg = 110.0;
    double refresh_hz = 90.0;
    LensProfile lens;
    AcuityModel acuity;

    // Pinhole focal lengths of the rendered (pre-lens) eye image, in pixels.
    double focalXPx() const;
    double focalYPx() const;
    // ω*: the angular size of one display pixel at the image centre, the coarser of the two
    // axes, so that a layer sampled at s = ω/ω* meets the MAR on both axes.
    double pixelAngleDeg() const;
    // The linear down-sampling factor a layer starting at eccentricity e may use: ω(e)/ω*,
    // never below 1 (Eq. 1).
    double scaleAt(double eccentricity_deg) const;
    double frameBudgetMs() const { return 1000.0 / refresh_hz; }
};

// The paper's two display classes: 1920×2160 per eye ("-H" workloads, the default) and
// 1280×1600 per eye ("-L").
HmdProfile defaultHmdProfile();
HmdProfile lowResHmdProfile();

// Parses a profile from TOML text. The grammar:
//   name = "string"                                   (optional)
//   [display] width_px, height_px (integers 16…16384), refresh_hz (1…1000)
//   [fov]     horizontal_deg, vertical_deg (10…170)
//   [lens]    k1, k2 (−1…4), chroma_red_scale, chroma_blue_scale (0.9…1.1)
//   [acuity]  omega0_deg (1e−4…1), slope (0…1)
// Absent keys keep the default profile's values; unknown keys and out-of-range values are errors.
Expected<HmdProfile> parseHmdProfile(std::string_view toml_text, std::string_view source_name);
Expected<HmdProfile> loadHmdProfile(const std::string& path);
// "default", "low" (or "1280x1600"), or a path to a TOML file.
Expected<HmdProfile> hmdProfileByName(const std::string& name_or_path);
std::string hmdProfileToToml(const HmdProfile& p);

}  // namespace qvr
