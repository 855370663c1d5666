// Option parsers shared by several subcommands, so that `--gaze` means the same everywhere.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

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

}  // namespace qvr::cli
