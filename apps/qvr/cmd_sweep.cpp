// `qvr sweep`: qvr, sw, ffr, aimd and a fixed-e1 grid on conditions drawn from a seed, each run
// for real and predicted (qvr/experiment/sweep.h); this file parses the options.
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "options.h"
#include "qvr/experiment/sweep.h"
#include "qvr/runtime/server_process.h"

namespace qvr::cli {

using namespace qvr::experiment;  // the experiment part this command drives

namespace {

int runSweepCommand(const SweepArgs& args) {
    auto options = sweepOptions(args);
    if (!options) {
        std::fprintf(stderr, "qvr sweep: %s\n", options.error().c_str());
        return 2;
    }
    for (const std::string& why : options->skipped_designs)
        std::fprintf(stderr, "qvr sweep: leaving out %s\n", why.c_str());
    const auto exe = runtime::selfExecutable();
    if (!exe) {
        std::fprintf(stderr, "qvr sweep: %s\n", exe.error().c_str());
        return 1;
    }
    options->executable = *exe;
    if (!options->from.empty()) {
        StoredConditionRunner stored(options->from);
        return runSweep(*options, stored);
    }
    ProcessRunner children;  // from here SIGINT and SIGTERM stop the sweep
    ProcessConditionRunner runner(*options, children);
    return runSweep(*options, runner);
}

}  // namespace

static Registered registerSweep(CLI::App& app) {
    auto a = std::make_shared<SweepArgs>(defaultSweepArgs());
    CLI::App* cmd = app.add_subcommand(
        "sweep",
        "Adaptive against fixed foveation on N conditions drawn from a seed: every "
        "design run for real and predicted, the claim's criteria judged");
    addSeedOption(cmd, a->seed, "Seed the conditions are drawn from");
    cmd->add_option("--conditions", a->conditions, "Conditions to draw (1..1000)")
        ->capture_default_str();
    cmd->add_option("--traces", a->traces,
                    "Comma-separated Mahimahi files, folders of *.down or trace:FILE[@MBPS] specs "
                    "(default: shared/data/network's, each also at 2 Mbit/s, and data/network's)");
    cmd->add_option("--rate-min", a->rate_min_mbps, "Slowest constant link, Mbit/s")
        ->capture_default_str();
    cmd->add_option("--rate-max", a->rate_max_mbps, "Fastest constant link, Mbit/s")
        ->capture_default_str();
    cmd->add_option("--share-min", a->share_min, "Smallest headset share")->capture_default_str();
    cmd->add_option("--share-max", a->share_max, "Largest headset share")->capture_default_str();
    cmd->add_option("--scenes", a->scenes, "Comma-separated scenes")->capture_default_str();
    cmd->add_option("--motions", a->motions, "Comma-separated head motions")->capture_default_str();
    cmd->add_option("--designs", a->designs,
                    "Adaptive designs of every take (one the runtime refuses is left out)")
        ->capture_default_str();
    cmd->add_option("--fixed-grid", a->fixed_grid, "Fixed e1 of the first take, degrees")
        ->capture_default_str();
    cmd->add_option("--repeats", a->repeats,
                    "Takes of the adaptive designs and the best fixed e1 after the first")
        ->capture_default_str();
    addFramesOption(cmd, a->frames, 20, 100000, "Frames per design per run");
    addHardwareOption(cmd, a->hardware, "Calibration for every run's prediction");
    cmd->add_flag("--cached-calibration", a->cached_calibration,
                  "Each scene's cached calibration as it is (default: measured afresh at the "
                  "scene's first run)");
    addProfileOption(cmd, a->profile, ProfileNames::kRuntime);
    addOutputFolderOption(cmd, a->out, "Output folder");
    cmd->add_flag("--dry-run", a->dry_run, "Print the conditions without running them");
    cmd->add_option("--from", a->from,
                    "Judge the runs an earlier sweep wrote in this folder (its seed, conditions, "
                    "repeats and designs) instead of running them");
    return {cmd, [a] { return runSweepCommand(*a); }};
}

QVR_REGISTER_COMMAND(93, registerSweep);

}  // namespace qvr::cli
