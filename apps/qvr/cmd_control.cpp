// `qvr control`: run a fovea-sizing policy (LIWC, software-reactive, fixed, oracle) over a
// workload under the ground-truth cost model and report per-frame e1, true and predicted
// latencies, and a summary (paper §4.1, §6.2).
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "options.h"
#include "qvr/controller/control_run.h"
#include "qvr/workload/synthetic.h"
#include "qvr/workload/trace_io.h"

namespace qvr::cli {

namespace {

// Table 1 of the paper gives background sizes and their Wi-Fi transfer times: 646 KB in 38 ms,
// 530 KB in 31 ms, … — about 137.6 Mbit/s of the link's nominal 200, an efficiency of 0.688
// applied to every nominal rate (docs/COST_MODEL.md).
constexpr double kLinkEfficiency = 0.688;

struct ControlOptions {
    std::string policy = "liwc";
    int frames = 300;
    std::string trace;
    std::string bench;
    std::string net = "wifi";
    double throughput_mbps = 0.0;
    double gpu_mhz = 500.0;
    double fixed_e1_deg = 5.0;
    bool compare = false;
    bool json = false;
};

double nominalMbps(const std::string& net) {
    if (net == "wifi")
        return 200.0;
    if (net == "lte")
        return 100.0;
    if (net == "5g")
        return 500.0;
    return 0.0;
}

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

int runControl(const ControlOptions& o) {
    WorkloadTrace trace;
    if (!o.trace.empty()) {
        auto loaded = loadWorkloadTrace(o.trace);
        if (!loaded) {
            std::fprintf(stderr, "qvr control: %s\n", loaded.error().c_str());
            return 2;
        }
        trace = std::move(loaded).value();
    } else {
        SyntheticSpec spec = defaultSyntheticSpec();
        if (!o.bench.empty()) {
            bool found = false;
            std::string names;
            for (const auto& s : paperSyntheticSuite()) {
                names += (names.empty() ? "" : ", ") + s.name;
                if (s.name == o.bench) {
                    spec = s;
                    found = true;
                }
            }
            if (!found) {
                std::fprintf(stderr, "qvr control: unknown --bench '%s' (choose %s)\n",
                             o.bench.c_str(), names.c_str());
                return 2;
            }
        }
        spec.frames = o.frames;
        trace = generateSyntheticWorkload(spec);
    }
    double mbps = o.throughput_mbps;
    if (mbps <= 0.0)
        mbps = nominalMbps(o.net) * kLinkEfficiency;
    GpuModel gpu;
    gpu.freq_mhz = o.gpu_mhz;
    const CostModel truth(trace.header, gpu, mbps * 1e6);

    auto run_one = [&](const std::string& name) -> Expected<ControlRun> {
        auto policy = makePolicy(name, trace.header, truth, o.fixed_e1_deg);
        if (!policy)
            return makeError(policy.error());
        return runPolicy(**policy, trace, truth, o.frames);
    };
    auto main_run = run_one(o.policy);
    if (!main_run) {
        std::fprintf(stderr, "qvr control: %s\n", main_run.error().c_str());
        return 2;
    }
    // The oracle is the yardstick every policy is measured against.
    auto oracle = o.policy == "oracle" ? main_run : run_one("oracle");
    const double vs_oracle = main_run->summary.frame_ms_mean / oracle->summary.frame_ms_mean;

    if (o.json) {
        nlohmann::json j;
        j["policy"] = main_run->policy;
        j["workload"] = {{"name", trace.header.name},
                         {"source", trace.header.source},
                         {"profile", trace.header.profile.name},
                         {"frames", trace.frames.size()}};
        j["hardware"] = {{"gpu_mhz", o.gpu_mhz}, {"throughput_mbps", mbps}};
        nlohmann::json frames = nlohmann::json::array();
        for (const auto& f : main_run->frames) {
            frames.push_back({{"frame", f.index},
                              {"motion", f.motion},
                              {"e1_deg", f.e1_deg},
                              {"e2_deg", f.e2_deg},
                              {"t_local_ms", f.t_local_ms},
                              {"t_remote_ms", f.t_remote_ms},
                              {"t_local_pred_ms", jsonNumber(f.t_local_pred_ms)},
                              {"t_remote_pred_ms", jsonNumber(f.t_remote_pred_ms)},
                              {"frame_ms", f.frameMs()},
                              {"latency_ratio", f.ratio()},
                              {"remote_bytes", f.remote_bytes}});
        }
        j["frames"] = std::move(frames);
        j["summary"] = summaryJson(main_run->summary);
        j["summary"]["oracle_frame_ms_mean"] = oracle->summary.frame_ms_mean;
        j["summary"]["frame_ms_vs_oracle"] = vs_oracle;
        if (o.compare) {
            nlohmann::json cmp;
            for (const char* name : {"liwc", "sw", "fixed", "oracle"}) {
                auto r = run_one(name);
                cmp[name] = summaryJson(r->summary);
            }
            j["compare"] = cmp;
        }
        std::printf("%s\n", j.dump(1).c_str());
        return 0;
    }

    fmt::print("workload {} ({}), {} frames, profile {}; GPU {} MHz, link {:.1f} Mbit/s\n",
               trace.header.name, trace.header.source, main_run->frames.size(),
               trace.header.profile.name, o.gpu_mhz, mbps);
    fmt::print("policy {}: frame by frame (every 20th)\n", main_run->policy);
    fmt::print("  {:>5} {:>7} {:>9} {:>9} {:>9} {:>9} {:>7}\n", "frame", "e1", "T_local",
               "T_remote", "pred_loc", "pred_rem", "ratio");
    for (const auto& f : main_run->frames) {
        if (f.index % 20 != 0 && f.index >= 10)
            continue;
        fmt::print("  {:>5} {:>7.2f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>7.3f}\n", f.index,
                   f.e1_deg, f.t_local_ms, f.t_remote_ms, f.t_local_pred_ms, f.t_remote_pred_ms,
                   f.ratio());
    }
    auto line = [](const std::string& name, const ControlSummary& s, double oracle_ms) {
        fmt::print(
            "  {:<7} frame {:7.3f} ms (p99 {:7.3f})  {:6.1f} fps  e1 {:5.1f}  "
            "{:>5.2f}x oracle  balanced from frame {}\n",
            name, s.frame_ms_mean, s.frame_ms_p99, 1000.0 / s.frame_ms_mean, s.e1_deg_mean,
            s.frame_ms_mean / oracle_ms,
            s.frames_to_balance ? std::to_string(*s.frames_to_balance) : "never");
    };
    fmt::print(
        "summary (frame = max(T_local, T_remote); balanced = |T_remote/T_local - 1| < "
        "{} from then on)\n",
        kBalanceTolerance);
    if (o.compare) {
        for (const char* name : {"liwc", "sw", "fixed", "oracle"}) {
            auto r = run_one(name);
            line(name, r->summary, oracle->summary.frame_ms_mean);
        }
    } else {
        line(main_run->policy, main_run->summary, oracle->summary.frame_ms_mean);
    }
    fmt::print("  local-only rendering of the same frames: {:.1f} ms\n", [&] {
        double sum = 0;
        for (int i = 0; i < static_cast<int>(main_run->frames.size()); ++i)
            sum += truth.localOnlyMs(trace.frames[static_cast<size_t>(i)]);
        return sum / std::max<size_t>(1, main_run->frames.size());
    }());
    return 0;
}

}  // namespace

static Registered registerControl(CLI::App& app) {
    auto o = std::make_shared<ControlOptions>();
    CLI::App* cmd = app.add_subcommand(
        "control", "Run a fovea-sizing policy over a workload and report e1 and latencies");
    cmd->add_option("--policy", o->policy,
                    "liwc (the learned controller), sw (software-reactive, 2-frame lag), fixed "
                    "(e1 = 5 deg, the paper's FFR) or oracle (knows each frame's true cost)")
        ->check(CLI::IsMember({"liwc", "sw", "fixed", "oracle"}))
        ->capture_default_str();
    addFramesOption(cmd, o->frames, 1, 1000000, "Frames to run");
    auto* trace = cmd->add_option("--trace", o->trace,
                                  "Workload trace file (JSON lines, docs/WORKLOAD_FORMAT.md)")
                      ->check(readableFile());
    cmd->add_option("--bench", o->bench,
                    "A workload of the synthetic suite (synthetic-doom3-h, synthetic-grid, ...); "
                    "default: synthetic-default")
        ->excludes(trace);
    cmd->add_option("--net", o->net, "Network profile: wifi (200 Mbit/s), lte (100), 5g (500)")
        ->check(CLI::IsMember({"wifi", "lte", "5g"}))
        ->capture_default_str();
    cmd->add_option("--throughput-mbps", o->throughput_mbps,
                    "Effective link throughput in Mbit/s (overrides --net)")
        ->check(finiteRange(0.01, 1e6));
    cmd->add_option("--gpu-mhz", o->gpu_mhz, "Mobile GPU clock; rates scale linearly")
        ->check(finiteRange(50.0, 5000.0))
        ->capture_default_str();
    cmd->add_option("--e1", o->fixed_e1_deg, "e1 of the fixed policy, degrees")
        ->check(finiteRange(0.0, 90.0))
        ->capture_default_str();
    cmd->add_flag("--compare", o->compare, "Also run every other policy and compare");
    cmd->add_flag("--json", o->json, "Print machine-readable JSON");
    return {cmd, [o] { return runControl(*o); }};
}
QVR_REGISTER_COMMAND(30, registerControl);

}  // namespace qvr::cli
