// Runs a policy over a workload under the ground-truth cost model (`qvr control`).
#include "qvr/controller/control_run.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "qvr/controller/liwc.h"

namespace qvr {

ControlRun runPolicy(FoveaPolicy& policy, const WorkloadTrace& trace, const CostModel& truth,
                     int frames) {
    ControlRun run;
    run.policy = std::string(policy.name());
    const int n = std::min<int>(frames, static_cast<int>(trace.frames.size()));
    run.frames.reserve(static_cast<size_t>(std::max(0, n)));
    uint16_t motion = 0;
    for (int i = 0; i < n; ++i) {
        const WorkloadFrame& f = trace.frames[static_cast<size_t>(i)];
        const Decision d = policy.decide(f);
        if (auto* liwc = dynamic_cast<LiwcPolicy*>(&policy))
            motion = liwc->lastMotion();
        const LayerPlan plan = truth.planner().plan(f.gaze, d.e1_deg);
        const FrameCost c = truth.cost(f, plan);
        const FrameMeasurement m = measureFrame(i, plan, c, truth.throughputBps());
        policy.observe(m);

        ControlFrame cf;
        cf.index = i;
        cf.motion = motion;
        cf.e1_deg = plan.e1_deg;
        cf.e2_deg = plan.e2_deg;
        cf.t_local_ms = c.local_ms;
        cf.t_remote_ms = c.remote_ms;
        cf.t_local_pred_ms = d.t_local_pred_ms;
        cf.t_remote_pred_ms = d.t_remote_pred_ms;
        cf.remote_bytes = c.bytes.total();
        run.frames.push_back(cf);
    }
    run.summary = summarize(run.frames);
    return run;
}

ControlSummary summarize(const std::vector<ControlFrame>& frames, double tolerance) {
    ControlSummary s;
    s.frames = static_cast<int>(frames.size());
    if (frames.empty())
        return s;
    std::vector<double> frame_ms;
    double err_l = 0, err_r = 0;
    int n_l = 0, n_r = 0;
    for (const auto& f : frames) {
        frame_ms.push_back(f.frameMs());
        s.frame_ms_mean += f.frameMs();
        s.e1_deg_mean += f.e1_deg;
        s.remote_bytes_mean += f.remote_bytes;
        if (std::isfinite(f.t_local_pred_ms) && f.t_local_ms > 0) {
            err_l += std::fabs(f.t_local_pred_ms - f.t_local_ms) / f.t_local_ms;
            ++n_l;
        }
        if (std::isfinite(f.t_remote_pred_ms) && f.t_remote_ms > 0) {
            err_r += std::fabs(f.t_remote_pred_ms - f.t_remote_ms) / f.t_remote_ms;
            ++n_r;
        }
    }
    const double n = static_cast<double>(frames.size());
    s.frame_ms_mean /= n;
    s.e1_deg_mean /= n;
    s.remote_bytes_mean /= n;
    s.prediction_error_local_pct = n_l ? 100.0 * err_l / n_l : 0.0;
    s.prediction_error_remote_pct = n_r ? 100.0 * err_r / n_r : 0.0;
    std::sort(frame_ms.begin(), frame_ms.end());
    s.frame_ms_p99 =
        frame_ms[std::min(frame_ms.size() - 1, static_cast<size_t>(std::ceil(0.99 * n)) - 1)];
    s.ratio_final = frames.back().ratio();
    // Walk back from the end while the ratio stays within tolerance.
    int first = s.frames;
    for (int i = s.frames - 1; i >= 0; --i) {
        if (std::fabs(frames[static_cast<size_t>(i)].ratio() - 1.0) < tolerance)
            first = i;
        else
            break;
    }
    if (first < s.frames)
        s.frames_to_balance = first;
    return s;
}

Expected<std::unique_ptr<FoveaPolicy>> makePolicy(const std::string& name,
                                                  const WorkloadHeader& header,
                                                  const CostModel& truth, double fixed_e1_deg) {
    if (name == "liwc")
        return std::unique_ptr<FoveaPolicy>(std::make_unique<LiwcPolicy>(header));
    if (name == "sw")
        return makeSoftwareReactivePolicy(header);
    if (name == "fixed")
        return std::unique_ptr<FoveaPolicy>(std::make_unique<FixedPolicy>(fixed_e1_deg));
    if (name == "oracle")
        return makeOraclePolicy(header, truth);
    return makeError(fmt::format("unknown policy '{}' (choose liwc, sw, fixed or oracle)", name));
}

}  // namespace qvr
