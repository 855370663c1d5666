// `qvr validate`: the simulator's correlation sheet (qvr/experiment/validation.h): checks its
// options and takes the sheet.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/experiment/validation.h"
#include "qvr/runtime/server_process.h"
#include "qvr/sim/hardware.h"

namespace qvr::cli {

using namespace qvr::experiment;  // the experiment part this command drives

namespace {

namespace fs = std::filesystem;

struct ValidateOptions {
    std::string designs = "local,remote,ffr,sw,qvr";
    std::string links;  // default: wifi,lte,5g and the ATT Mahimahi trace when found
    std::string scenes = "builtin:room,openarena:oa_dm5";
    std::string depths = "1,2";
    std::string motions = "default";
    std::string shares = "1";
    std::string calibration_scene;  // empty: each scene calibrated on itself
    int frames = 40;
    int reps = 1;
    // A run taken again when its speed probes say the machine was not steady over it.
    int retakes = 1;
    std::string hardware;  // a calibration to use instead of calibrating (one scene only)
    std::string calibrate = "per-rep";  // or "once": when each scene is calibrated
    std::string profile = "default";
    std::string out = "qvr-validate";
    bool dry_run = false;
};

std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t comma = s.find(',', start);
        const std::string item =
            s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (!item.empty())
            out.push_back(item);
        if (comma == std::string::npos)
            break;
        start = comma + 1;
    }
    return out;
}

int runValidate(const ValidateOptions& o) {
    const auto exe = runtime::selfExecutable();
    if (!exe) {
        std::fprintf(stderr, "qvr validate: %s\n", exe.error().c_str());
        return 1;
    }
    ProcessRunner runner;  // from here SIGINT and SIGTERM stop the sheet
    std::vector<std::string> links = splitList(o.links);
    if (o.links.empty()) {
        links = {"wifi", "lte", "5g"};
        const std::string att = findMahimahiTrace("ATT-LTE-driving-2016.down");
        if (!att.empty())
            links.push_back("trace:" + att);
        else
            std::fprintf(stderr,
                         "qvr validate: no ATT-LTE-driving-2016.down found (shared/data/network); "
                         "validating without a Mahimahi trace\n");
    }
    const std::vector<std::string> scenes = splitList(o.scenes);
    std::vector<int> depths;
    for (const std::string& d : splitList(o.depths)) {
        if (d != "1" && d != "2") {
            std::fprintf(stderr, "qvr validate: --depths takes 1 and/or 2, got '%s'\n", d.c_str());
            return 2;
        }
        depths.push_back(d == "1" ? 1 : 2);
    }
    std::vector<double> shares;
    for (const std::string& s : splitList(o.shares)) {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !(v > 0.05 && v <= 1.0)) {
            std::fprintf(stderr,
                         "qvr validate: --headset-shares takes shares in (0.05, 1], got '%s'\n",
                         s.c_str());
            return 2;
        }
        shares.push_back(v);
    }
    const std::vector<std::string> motions = splitList(o.motions);
    if (links.empty() || scenes.empty() || depths.empty() || splitList(o.designs).empty() ||
        motions.empty() || shares.empty()) {
        std::fprintf(stderr,
                     "qvr validate: empty --links, --scenes, --depths, --designs, --motions or "
                     "--headset-shares\n");
        return 2;
    }
    for (const std::string& m : motions) {
        std::error_code ec;
        if (m != "default" && m != "still" && !fs::is_regular_file(m, ec)) {
            std::fprintf(stderr, "qvr validate: --motions: %s: no such file\n", m.c_str());
            return 2;
        }
    }
    if (!o.hardware.empty() && scenes.size() != 1 && o.calibration_scene.empty()) {
        std::fprintf(stderr,
                     "qvr validate: --hardware is one scene's calibration; give one "
                     "--scenes\n");
        return 2;
    }
    std::string hardware;  // absolute, as the runs are given it
    if (!o.hardware.empty()) {
        auto hw = loadHardwareConfig(o.hardware, 500.0);
        if (!hw) {
            std::fprintf(stderr, "qvr validate: --hardware: %s\n", hw.error().c_str());
            return 2;
        }
        if (!hw->runtime_pipeline) {
            std::fprintf(stderr,
                         "qvr validate: --hardware: %s is not a calibration (qvr calibrate --out "
                         "FILE writes one)\n",
                         o.hardware.c_str());
            return 2;
        }
        std::error_code aec;
        hardware = fs::absolute(o.hardware, aec).string();
    }
    const CalibrationPolicy policy =
        o.calibrate == "once" ? CalibrationPolicy::kOnce : CalibrationPolicy::kPerRep;
    return runValidation({.executable = *exe,
                          .designs = o.designs,
                          .links = links,
                          .scenes = scenes,
                          .depths = depths,
                          .motions = motions,
                          .headset_shares = shares,
                          .calibration_scene = o.calibration_scene,
                          .frames = o.frames,
                          .reps = o.reps,
                          .retakes = o.retakes,
                          .calibrate = policy,
                          .hardware = hardware,
                          .profile = o.profile,
                          .out = o.out,
                          .dry_run = o.dry_run},
                         runner);
}

}  // namespace

static Registered registerValidate(CLI::App& app) {
    auto o = std::make_shared<ValidateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "validate",
        "Calibrate, then run qvr run over links x scenes x pipeline depths and tabulate the "
        "calibrated simulator's prediction errors");
    cmd->add_option("--designs", o->designs, "Designs of every run")->capture_default_str();
    cmd->add_option("--links", o->links,
                    "Comma-separated qvr run --net specs (default: wifi,lte,5g and the ATT "
                    "Mahimahi trace of shared/data/network)");
    cmd->add_option("--scenes", o->scenes, "Comma-separated scenes")->capture_default_str();
    cmd->add_option("--depths", o->depths, "Frames in flight: 1, 2 or 1,2")->capture_default_str();
    cmd->add_option("--motions", o->motions, "Comma-separated head motions of every run")
        ->capture_default_str();
    cmd->add_option("--headset-shares", o->shares,
                    "Comma-separated headset shares of every run (qvr run --headset-share)")
        ->capture_default_str();
    cmd->add_option("--calibration-scene", o->calibration_scene,
                    "Calibrate on this scene only and predict every scene's runs with it (out of "
                    "sample); default: each scene calibrated on itself");
    addFramesOption(cmd, o->frames, 5, 100000, "Frames per design per run");
    addInt(cmd, "--reps", o->reps, "Repetitions of every condition", 1, 20);
    addInt(cmd, "--retakes", o->retakes,
           "Take a run again, up to this many times, when its speed probes moved over 10% across "
           "it or from the calibration's; the steadiest take counts",
           0, 5);
    addHardwareOption(cmd, o->hardware, "Use this calibration instead of calibrating (one scene)");
    cmd->add_option("--calibrate", o->calibrate,
                    "per-rep: each repetition calibrates each scene anew before its runs; once: "
                    "one calibration per scene before any run")
        ->check(CLI::IsMember({"per-rep", "once"}))
        ->capture_default_str();
    addProfileOption(cmd, o->profile, ProfileNames::kRuntime);
    addOutputFolderOption(cmd, o->out, "Output folder");
    cmd->add_flag("--dry-run", o->dry_run, "Print the commands without running them");
    return {cmd, [o] { return runValidate(*o); }};
}

QVR_REGISTER_COMMAND(92, registerValidate);

}  // namespace qvr::cli
