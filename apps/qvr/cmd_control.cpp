// `qvr control`: run a fovea-sizing policy (LIWC, software-reactive, fixed, oracle) over a
// workload under the ground-truth cost model and report per-frame e1, true and predicted
// latencies, and a summary (paper §4.1, §6.2); the run and its report are controller's
// (qvr/controller/control_report.h).
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "command_error.h"
#include "commands.h"
#include "qvr/controller/control_report.h"

namespace qvr::cli {

namespace {

struct ControlOptions {
    ControlPlan plan;
    std::string trace;
    std::string bench;
    std::string net = "wifi";
    bool json = false;
};

int runControlCommand(ControlOptions o) {
    auto trace = controlWorkload(o.trace, o.bench, o.plan.frames);
    if (!trace)
        return fail("control", trace.error(), 2);
    if (o.plan.throughput_mbps <= 0.0) {
        auto mbps = effectiveThroughputMbps(o.net);
        if (!mbps)
            return fail("control", "--net: " + mbps.error(), 2);
        o.plan.throughput_mbps = *mbps;
    }
    auto report = runControl(*trace, o.plan);
    if (!report)
        return fail("control", report.error(), 2);
    if (o.json)
        std::printf("%s\n", controlReportJson(*report).c_str());
    else
        fmt::print("{}", controlReportText(*report));
    return 0;
}

}  // namespace

static Registered registerControl(CLI::App& app) {
    auto o = std::make_shared<ControlOptions>();
    CLI::App* cmd = app.add_subcommand(
        "control", "Run a fovea-sizing policy over a workload and report e1 and latencies");
    cmd->add_option("--policy", o->plan.policy,
                    "liwc (the learned controller), sw (software-reactive, 2-frame lag), fixed "
                    "(e1 = 5 deg, the paper's FFR) or oracle (knows each frame's true cost)")
        ->check(CLI::IsMember({"liwc", "sw", "fixed", "oracle"}))
        ->capture_default_str();
    addFramesOption(cmd, o->plan.frames, 1, 1000000, "Frames to run");
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
    cmd->add_option("--throughput-mbps", o->plan.throughput_mbps,
                    "Effective link throughput in Mbit/s (overrides --net)")
        ->check(finiteRange(0.01, 1e6));
    addFinite(cmd, "--gpu-mhz", o->plan.gpu_mhz, "Mobile GPU clock; rates scale linearly", 50.0,
              5000.0);
    addFinite(cmd, "--e1", o->plan.fixed_e1_deg, "e1 of the fixed policy, degrees", 0.0, 90.0);
    cmd->add_flag("--compare", o->plan.compare, "Also run every other policy and compare");
    addJsonFlag(cmd, o->json);
    return {cmd, [o] { return runControlCommand(*o); }};
}
QVR_REGISTER_COMMAND(30, registerControl);

}  // namespace qvr::cli
