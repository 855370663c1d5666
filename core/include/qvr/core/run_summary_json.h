// The one spelling of a run's headline statistics in JSON: every summary.json that reports a run
// (`qvr client`, `qvr run` per design, `qvr sim --pipeline runtime`) starts from these keys, so
// the same statistic has the same name everywhere.
#pragma once

#include <nlohmann/json.hpp>

#include "qvr/core/run_summary.h"

namespace qvr {

// fps_mean, mtp_ms_mean, mtp_ms_p99, bytes_per_frame_mean, e1_deg_mean, frames, frames_reused.
nlohmann::json runStatsJson(const RunStats& s);

}  // namespace qvr
