// `qvr bench uca`'s report: UCA (paper §4.2, Eq. 3–4) against the two-pass reference and the
// OpenCV anchor, the copy-bandwidth floor and PSNR/SSIM, read from compose's UcaBenchResult with
// the host it ran on.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "qvr/compose/uca_benchmark.h"

namespace qvr::experiment {

nlohmann::json ucaBenchJson(const UcaBenchOptions& options, const UcaBenchResult& result);
std::string ucaBenchText(const UcaBenchOptions& options, const UcaBenchResult& result);

}  // namespace qvr::experiment
