// Option parsers shared by several subcommands, so that `--gaze` means the same everywhere.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "qvr/foveation/eye_geometry.h"

namespace qvr::cli {

// "X,Y": gaze angles in degrees right/up of the optical axis, each finite and within ±80.
inline bool parseGazeDeg(const std::string& text, Gaze& gaze) {
    double x = 0, y = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf%c", &x, &y, &tail) != 2)
        return false;
    if (!std::isfinite(x) || !std::isfinite(y) || std::fabs(x) > 80 || std::fabs(y) > 80)
        return false;
    gaze = {x, y};
    return true;
}

// --lod-px (render/draw_list.h): each view draws every scene cluster at the coarsest level of
// detail whose vertices move at most this many of the view's own pixels; 0 draws full detail.
inline CLI::Option* addLodOption(CLI::App* cmd, float& lod_px) {
    return cmd
        ->add_option("--lod-px", lod_px,
                     "Level of detail: largest vertex move in each view's own pixels (0: full "
                     "detail)")
        ->check(CLI::Range(0.0, 16.0))
        ->capture_default_str();
}

}  // namespace qvr::cli
