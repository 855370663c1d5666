// `qvr control`'s run and report (control_report.h).
#include "qvr/controller/control_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "qvr/core/link_efficiency.h"
#include "qvr/core/link_spec.h"
#include "qvr/workload/synthetic.h"
#include "qvr/workload/trace_io.h"

namespace qvr {

Expected<WorkloadTrace> controlWorkload(const std::string& trace_path, const std::string& bench,
                                        int frames) {
    if (!trace_path.empty())
        return loadWorkloadTrace(trace_path);
    SyntheticSpec spec = defaultSyntheticSpec();
    if (!bench.empty()) {
        bool found = false;
        std::string names;
        for (const auto& s : paperSyntheticSuite()) {
            names += (names.empty() ? "" : ", ") + s.name;
            if (s.name == bench) {
                spec = s;
                found = true;
            }
        }
        if (!found)
            return makeError("unknown --bench '" + bench + "' (choose " + names + ")");
    }
    spec.frames = frames;
    return generateSyntheticWorkload(spec);
}

Expected<double> effectiveThroughputMbps(const std::string& net) {
    auto spec = parseLinkSpec(net);
    if (!spec)
        return makeError(spec.error());
    if (spec->rate_bps <= 0.0 || spec->options > 0)
        return makeError("'" + net + "' is not a link profile with a nominal rate");
    return spec->rate_bps * 1e-6 * calibratedLinkEfficiency();
}

Expected<ControlReport> runControl(const WorkloadTrace& trace, const ControlPlan& plan) {
    GpuModel gpu;
    gpu.freq_mhz = plan.gpu_mhz;
    const CostModel truth(trace.header, gpu, plan.throughput_mbps * 1e6);
    auto run_one = [&](const std::string& name) -> Expected<ControlRun> {
        auto policy = makePolicy(name, trace.header, truth, plan.fixed_e1_deg);
        if (!policy)
            return makeError(policy.error());
        return runPolicy(**policy, trace, truth, plan.frames);
    };
    ControlReport report;
    report.plan = plan;
    report.workload = trace.header;
    report.workload_frames = trace.frames.size();
    auto run = run_one(plan.policy);
    if (!run)
        return makeError(run.error());
    report.run = std::move(*run);
    report.oracle = plan.policy == "oracle" ? report.run.summary : run_one("oracle")->summary;
    if (plan.compare)
        for (const char* name : kComparedPolicies)
            report.compared.emplace_back(name, run_one(name)->summary);
    double sum = 0;
    for (size_t i = 0; i < report.run.frames.size(); ++i)
        sum += truth.localOnlyMs(trace.frames[i]);
    report.local_only_ms_mean = sum / std::max<size_t>(1, report.run.frames.size());
    return report;
}

namespace {

nlohmann::json jsonNumber(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json summaryJson(const ControlSummary& s) {
    return {{"frames", s.frames},
            {"frame_ms_mean", s.frame_ms_mean},
            {"frame_ms_p99", s.frame_ms_p99},
            {"fps_mean", s.frame_ms_mean > 0 ? 1000.0 / s.frame_ms_mean : 0.0},
            {"e1_deg_mean", s.e1_deg_mean},
            {"latency_ratio_final", s.ratio_final},
            {"remote_bytes_mean", s.remote_bytes_mean},
            {"prediction_error_local_pct", s.prediction_error_local_pct},
            {"prediction_error_remote_pct", s.prediction_error_remote_pct},
            {"frames_to_balance",
             s.frames_to_balance ? nlohmann::json(*s.frames_to_balance) : nlohmann::json(nullptr)},
            {"balance_tolerance", kBalanceTolerance}};
}

nlohmann::json frameJson(const ControlFrame& f) {
    return {{"frame", f.index},
            {"motion", f.motion},
            {"e1_deg", f.e1_deg},
            {"e2_deg", f.e2_deg},
            {"t_local_ms", f.t_local_ms},
            {"t_remote_ms", f.t_remote_ms},
            {"t_local_pred_ms", jsonNumber(f.t_local_pred_ms)},
            {"t_remote_pred_ms", jsonNumber(f.t_remote_pred_ms)},
            {"frame_ms", f.frameMs()},
            {"latency_ratio", f.ratio()},
            {"remote_bytes", f.remote_bytes}};
}

std::string summaryLine(const std::string& name, const ControlSummary& s, double oracle_ms) {
    return fmt::format(
        "  {:<7} frame {:7.3f} ms (p99 {:7.3f})  {:6.1f} fps  e1 {:5.1f}  "
        "{:>5.2f}x oracle  balanced from frame {}\n",
        name, s.frame_ms_mean, s.frame_ms_p99, 1000.0 / s.frame_ms_mean, s.e1_deg_mean,
        s.frame_ms_mean / oracle_ms,
        s.frames_to_balance ? std::to_string(*s.frames_to_balance) : "never");
}

}  // namespace

std::string controlReportJson(const ControlReport& r) {
    nlohmann::json j;
    j["policy"] = r.run.policy;
    j["workload"] = {{"name", r.workload.name},
                     {"source", r.workload.source},
                     {"profile", r.workload.profile.name},
                     {"frames", r.workload_frames}};
    j["hardware"] = {{"gpu_mhz", r.plan.gpu_mhz}, {"throughput_mbps", r.plan.throughput_mbps}};
    nlohmann::json frames = nlohmann::json::array();
    for (const auto& f : r.run.frames)
        frames.push_back(frameJson(f));
    j["frames"] = std::move(frames);
    j["summary"] = summaryJson(r.run.summary);
    j["summary"]["oracle_frame_ms_mean"] = r.oracle.frame_ms_mean;
    j["summary"]["frame_ms_vs_oracle"] = r.run.summary.frame_ms_mean / r.oracle.frame_ms_mean;
    if (r.plan.compare) {
        nlohmann::json cmp;
        for (const auto& [name, s] : r.compared)
            cmp[name] = summaryJson(s);
        j["compare"] = cmp;
    }
    return j.dump(1);
}

std::string controlReportText(const ControlReport& r) {
    std::string t =
        fmt::format("workload {} ({}), {} frames, profile {}; GPU {} MHz, link {:.1f} Mbit/s\n",
                    r.workload.name, r.workload.source, r.run.frames.size(),
                    r.workload.profile.name, r.plan.gpu_mhz, r.plan.throughput_mbps);
    t += fmt::format("policy {}: frame by frame (every 20th)\n", r.run.policy);
    t += fmt::format("  {:>5} {:>7} {:>9} {:>9} {:>9} {:>9} {:>7}\n", "frame", "e1", "T_local",
                     "T_remote", "pred_loc", "pred_rem", "ratio");
    for (const auto& f : r.run.frames) {
        if (f.index % 20 != 0 && f.index >= 10)
            continue;
        t += fmt::format("  {:>5} {:>7.2f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>7.3f}\n", f.index,
                         f.e1_deg, f.t_local_ms, f.t_remote_ms, f.t_local_pred_ms,
                         f.t_remote_pred_ms, f.ratio());
    }
    t += fmt::format(
        "summary (frame = max(T_local, T_remote); balanced = |T_remote/T_local - 1| < "
        "{} from then on)\n",
        kBalanceTolerance);
    if (r.plan.compare) {
        for (const auto& [name, s] : r.compared)
            t += summaryLine(name, s, r.oracle.frame_ms_mean);
    } else {
        t += summaryLine(r.run.policy, r.run.summary, r.oracle.frame_ms_mean);
    }
    t +=
        fmt::format("  local-only rendering of the same frames: {:.1f} ms\n", r.local_only_ms_mean);
    return t;
}

}  // namespace qvr
