// Runs a policy over a workload under a cost model, frame by frame: decide, pay the true cost,
// measure, observe. The engine of `qvr control`; the simulator drives policies the same way
// with its own pipeline timing.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "qvr/controller/policy.h"
#include "qvr/core/expected.h"

namespace qvr {

struct ControlFrame {
    int64_t index = 0;
    uint16_t motion = 0;
    double e1_deg = 0.0;
    double e2_deg = 0.0;
    double t_local_ms = 0.0;  // truth under the cost model
    double t_remote_ms = 0.0;
    double t_local_pred_ms = 0.0;  // the policy's prediction
    double t_remote_pred_ms = 0.0;
    double remote_bytes = 0.0;
    double frameMs() const { return t_local_ms > t_remote_ms ? t_local_ms : t_remote_ms; }
    double ratio() const { return t_local_ms > 0 ? t_remote_ms / t_local_ms : 0.0; }
};

struct ControlSummary {
    int frames = 0;
    double frame_ms_mean = 0.0;  // mean of max(T_local, T_remote)
    double frame_ms_p99 = 0.0;
    double e1_deg_mean = 0.0;
    double ratio_final = 0.0;
    double remote_bytes_mean = 0.0;
    double prediction_error_local_pct = 0.0;  // mean |pred − true| / true, where predicted
    double prediction_error_remote_pct = 0.0;
    // First frame from which |T_remote/T_local − 1| stays under the tolerance; empty if never.
    std::optional<int> frames_to_balance;
};

struct ControlRun {
    std::string policy;
    std::vector<ControlFrame> frames;
    ControlSummary summary;
};

inline constexpr double kBalanceTolerance = 0.15;

ControlRun runPolicy(FoveaPolicy& policy, const WorkloadTrace& trace, const CostModel& truth,
                     int frames);
ControlSummary summarize(const std::vector<ControlFrame>& frames,
                         double tolerance = kBalanceTolerance);

// "liwc", "sw", "fixed" (e1 = 5°, or fixed_e1_deg) or "oracle".
Expected<std::unique_ptr<FoveaPolicy>> makePolicy(const std::string& name,
                                                  const WorkloadHeader& header,
                                                  const CostModel& truth,
                                                  double fixed_e1_deg = 5.0);

}  // namespace qvr
