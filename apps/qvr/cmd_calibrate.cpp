// `qvr calibrate`'s command line: parses the options and calls the experiment's calibration
// (qvr/experiment/calibration.h).
#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/core/text_file.h"
#include "qvr/experiment/calibration.h"
#include "qvr/experiment/host.h"

namespace qvr::cli {

using namespace qvr::experiment;  // the experiment part this command drives

namespace {

struct CalibrateCmdOptions {
    CalibrateOptions cal;
    std::string out;
    std::string json;
    std::string command_line;
};

int runCalibrate(CalibrateCmdOptions& o) {
    o.cal.verbose = true;
    fmt::print("qvr calibrate: {} on {}, profile {}, codec {}, LOD {} px, core {}{}\n",
               experiment::machineDescription(), o.cal.scene, o.cal.profile, o.cal.codec,
               o.cal.lod_px, o.cal.core, o.cal.quick ? ", quick" : "");
    auto cal = runCalibration(o.cal);
    if (!cal) {
        std::fprintf(stderr, "qvr calibrate: %s\n", cal.error().c_str());
        return 2;
    }
    cal->command = o.command_line;
    fmt::print("{}", calibrationSummaryText(*cal));
    const std::string json = o.json.empty() ? o.out + ".json" : o.json;
    Status written = writeTextFile(o.out, cal->toToml());
    if (written)
        written = writeJsonFile(json, cal->toJson());
    if (!written) {
        std::fprintf(stderr, "qvr calibrate: %s\n", written.error().c_str());
        return 1;
    }
    fmt::print("  wrote {} (qvr sim --hardware / qvr run --hardware) and {}\n", o.out, json);
    return 0;
}

}  // namespace

static Registered registerCalibrate(CLI::App& app) {
    auto o = std::make_shared<CalibrateCmdOptions>();
    CLI::App* cmd = app.add_subcommand(
        "calibrate",
        "Measure this machine's runtime costs (render, encode, decode, UCA, ring counts) and "
        "write a hardware file for the runtime pipeline model");
    addOutputFileOption(cmd, o->out, "Hardware file to write (TOML)");
    cmd->add_option("--json", o->json, "JSON copy (default: OUT.json)")->check(writableFile());
    cmd->add_option("--scene", o->cal.scene, "Scene the render costs are measured on")
        ->capture_default_str();
    addProfileOption(cmd, o->cal.profile, ProfileNames::kRuntime);
    addCodecOption(cmd, o->cal.codec);
    // Any core number, also one this machine lacks: the calibration then measures without its
    // speed probe and says why (tests/cli/run_outputs_test.sh).
    addInt(cmd, "--core", o->cal.core, "Core to pin to (-1: none)", -1, 4096);
    addLodOption(cmd, o->cal.lod_px);
    cmd->add_flag("--quick", o->cal.quick, "Fewer samples (what qvr run does before a run)");
    return {cmd, [o] {
                o->command_line = fmt::format(
                    "qvr calibrate --out {} --scene {} --profile {} --codec {} --lod-px {} "
                    "--core {}{}",
                    o->out, o->cal.scene, o->cal.profile, o->cal.codec, o->cal.lod_px, o->cal.core,
                    o->cal.quick ? " --quick" : "");
                return runCalibrate(*o);
            }};
}

QVR_REGISTER_COMMAND(91, registerCalibrate);
static Registered registerCoRunLoad(CLI::App& app) {
    auto o = std::make_shared<CalibrateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "corun-load",
        "qvr calibrate's second-core load (internal: one side's frames while told to)");
    cmd->group("");  // not listed: qvr calibrate starts it
    cmd->add_option("--scene", o->scene)->required();
    addProfileOption(cmd, o->profile, ProfileNames::kRuntime)->required();
    addLodOption(cmd, o->lod_px);
    cmd->add_option("--core", o->core)->required()->check(CLI::Range(0, 4095));
    addCodecOption(cmd, o->codec);
    auto mix = std::make_shared<std::string>("server");
    cmd->add_option("--mix", *mix)->check(CLI::IsMember({"server", "headset", "probe"}));
    return {cmd, [o, mix] { return runCoRunLoad(*o, *mix); }};
}
QVR_REGISTER_COMMAND(92, registerCoRunLoad);

}  // namespace qvr::cli
