// Headsets per render server at a target frame rate (capacity.h).
#include "qvr/sim/capacity.h"

#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "qvr/workload/trace_io.h"

namespace qvr {

namespace {

// One headset's server time per frame: the modelled one is N-fold (each headset waits on all N).
double perHeadsetServerMs(const CapacityPoint& p) {
    return p.summary.server_busy_ms_mean / p.factors.server;
}

}  // namespace

SideFactors capacityFactors(int headsets, double headset_share, bool share_one_core) {
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
                                         const CapacityOptions& o,
                                         const CapacityLayerTriangles& layer_triangles) {
    if (o.target_fps <= 0.0)
        return makeError("the target FPS must be positive");
    CapacityResult result;
    int below = 0;
    for (int n = 1; n <= o.max_headsets && (o.every_count || below < 2); ++n) {
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
        cfg.costs =
            costs.atSpeed(p.factors.headset * o.speed.headset, p.factors.server * o.speed.server);
        cfg.costs.link_delay_ms += delay_ms;
        cfg.pipeline_depth = o.pipeline_depth;
        cfg.wait_limit_ms = o.wait_limit_ms;
        cfg.frames = o.frames;
        cfg.warmup_frames = o.warmup_frames;
        cfg.layer_triangles = layer_triangles;
        p.summary = simulateRuntime(trace, cfg, **link).summary;
        // The summary's server time is the N-fold one: each headset's own share of it is 1/N.
        p.server_utilisation = perHeadsetServerMs(p) * n * p.summary.fps_mean / 1000.0;
        below += p.summary.fps_mean < o.target_fps ? 1 : 0;
        result.points.push_back(std::move(p));
    }
    result.headsets = headsetsAtTarget(result.points, o.target_fps);
    return result;
}

Expected<CapacityInputs> loadCapacityInputs(const std::string& hardware_path,
                                            const std::string& trace_path) {
    auto hw = loadHardwareConfig(hardware_path, 500.0);
    if (!hw)
        return makeError("--hardware: " + hw.error());
    if (!hw->runtime_pipeline)
        return makeError("--hardware: " + hardware_path +
                         " is not a calibration (qvr calibrate --out FILE writes one)");
    auto trace = loadWorkloadTrace(trace_path);
    if (!trace)
        return makeError("--trace: " + trace.error());
    if (trace->frames.empty())
        return makeError("--trace: the workload has no frames");
    return CapacityInputs{std::move(*trace), hw->runtime};
}

std::string capacityText(const CapacityResult& r, const CapacityOptions& o) {
    std::string text = fmt::format("qvr capacity: {} on {}, target {:g} FPS per headset\n",
                                   designLabel(o.design, o.fixed_e1_deg), o.net, o.target_fps);
    if (o.speed.headset != 1.0 || o.speed.server != 1.0)
        text += fmt::format("  at x{:.3f} the calibration's headset times, x{:.3f} its server's\n",
                            o.speed.headset, o.speed.server);
    for (const CapacityPoint& p : r.points)
        text += fmt::format(
            "  {:2} headsets: {:6.1f} FPS  MTP p99 {:7.1f} ms  server {:5.1f} ms per "
            "headset-frame, busy {:3.0f}%\n",
            p.headsets, p.summary.fps_mean, p.summary.mtp_ms_p99, perHeadsetServerMs(p),
            100.0 * p.server_utilisation);
    text += fmt::format("  {} headsets per server at {:g} FPS\n", r.headsets, o.target_fps);
    return text;
}

std::string capacityJson(const CapacityResult& r, const CapacityOptions& o) {
    nlohmann::json points = nlohmann::json::array();
    for (const CapacityPoint& p : r.points)
        points.push_back({{"headsets", p.headsets},
                          {"headset_factor", p.factors.headset},
                          {"server_factor", p.factors.server},
                          {"fps_mean", p.summary.fps_mean},
                          {"mtp_ms_mean", p.summary.mtp_ms_mean},
                          {"mtp_ms_p99", p.summary.mtp_ms_p99},
                          {"bytes_per_frame_mean", p.summary.bytes_per_frame_mean},
                          {"e1_deg_mean", p.summary.e1_deg_mean},
                          {"server_ms_per_headset_frame", perHeadsetServerMs(p)},
                          {"server_utilisation", p.server_utilisation}});
    const nlohmann::json j = {{"design", designLabel(o.design, o.fixed_e1_deg)},
                              {"target_fps", o.target_fps},
                              {"net", o.net},
                              {"headset_share", o.headset_share},
                              {"headsets_share_one_core", o.headsets_share_one_core},
                              {"speed", {{"headset", o.speed.headset}, {"server", o.speed.server}}},
                              {"headsets_at_target", r.headsets},
                              {"points", points}};
    return j.dump(2) + "\n";
}

}  // namespace qvr
