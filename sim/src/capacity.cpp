// Headsets per render server at a target frame rate (capacity.h).
#include "qvr/sim/capacity.h"

#include <algorithm>

namespace qvr {

CapacityFactors capacityFactors(int headsets, double headset_share, bool share_one_core) {
    const double n = double(std::max(headsets, 1));
    const double own = 1.0 / std::clamp(headset_share, 1e-3, 1.0);
    return {share_one_core ? std::max(own, n) : own, n};
}

int headsetsAtTarget(const std::vector<CapacityPoint>& points, double target_fps) {
    int best = 0;
    for (const CapacityPoint& p : points) {
        if (p.summary.fps_mean < target_fps)
            break;
        best = p.headsets;
    }
    return best;
}

Expected<CapacityResult> predictCapacity(const WorkloadTrace& trace, const RuntimeCosts& costs,
                                         const CapacityOptions& o) {
    if (o.target_fps <= 0.0)
        return makeError("the target FPS must be positive");
    CapacityResult result;
    int below = 0;
    for (int n = 1; n <= o.max_headsets && below < 2; ++n) {
        double delay_ms = 0.0;
        auto link = makeRuntimeLink(o.net, &delay_ms);
        if (!link)
            return makeError(link.error());
        CapacityPoint p;
        p.headsets = n;
        p.factors = capacityFactors(n, o.headset_share, o.headsets_share_one_core);
        RuntimeSimConfig cfg;
        cfg.design = o.design;
        cfg.fixed_e1_deg = o.fixed_e1_deg;
        cfg.costs = costs.atSpeed(p.factors.headset, p.factors.server);
        cfg.costs.link_delay_ms += delay_ms;
        cfg.pipeline_depth = o.pipeline_depth;
        cfg.wait_limit_ms = o.wait_limit_ms;
        cfg.frames = o.frames;
        cfg.warmup_frames = o.warmup_frames;
        p.summary = simulateRuntime(trace, cfg, **link).summary;
        // The summary's server time is the N-fold one: each headset's own share of it is 1/N.
        p.server_utilisation =
            p.summary.server_busy_ms_mean / p.factors.server * n * p.summary.fps_mean / 1000.0;
        below += p.summary.fps_mean < o.target_fps ? 1 : 0;
        result.points.push_back(std::move(p));
    }
    result.headsets = headsetsAtTarget(result.points, o.target_fps);
    return result;
}

}  // namespace qvr
