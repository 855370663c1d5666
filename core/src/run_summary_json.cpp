// The headline statistics of a run summary as JSON (summary.json's shared keys).
#include "qvr/core/run_summary_json.h"

namespace qvr {

nlohmann::json runStatsJson(const RunStats& s) {
    return {{"fps_mean", s.fps_mean},           {"mtp_ms_mean", s.mtp_ms_mean},
            {"mtp_ms_p99", s.mtp_ms_p99},       {"bytes_per_frame_mean", s.bytes_per_frame_mean},
            {"e1_deg_mean", s.e1_deg_mean},     {"frames", s.frames},
            {"frames_reused", s.frames_reused}, {"frames_new_layers", s.frames_new_layers}};
}

}  // namespace qvr
