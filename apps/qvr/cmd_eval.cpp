// `qvr eval`: the paper's evaluation (§6: Fig. 12–15, Table 4) over the Table 3 suite, with
// CSV, gnuplot figures, summary.json and report.html in one folder.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "command_error.h"
#include "commands.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/eval_setup.h"

namespace qvr::cli {

namespace {

struct EvalCliOptions {
    EvalOptions eval;  // frames, jobs, out_dir, vsync_paced
    EvalInputs inputs;
};

std::string joinArgs(const EvalCliOptions& o) {
    std::string s = fmt::format(
        "qvr eval --suite {} --codec-model {} --frames {} --jobs {} --out {}", o.inputs.suite,
        o.inputs.codec_model, o.eval.frames, o.eval.jobs, o.eval.out_dir);
    if (o.eval.vsync_paced)
        s += " --vsync";
    if (!o.inputs.mahimahi.empty())
        s += " --mahimahi";
    for (const auto& m : o.inputs.mahimahi)
        s += " " + m;
    return s;
}

int runEval(const EvalCliOptions& o) {
    if (Status st = selectEvalSuite(o.inputs); !st)
        return fail("eval", st.error(), 2);
    fmt::print("suite: {}\n", suiteBenchNamesList());
    auto codec = evalCodecModel(o.inputs);
    if (!codec)
        return fail("eval", codec.error(), 2);
    EvalOptions opts = o.eval;
    opts.hardware_path = o.inputs.hardware;
    opts.codec_model = *codec;
    opts.mahimahi_traces = o.inputs.mahimahi;
    opts.benches = o.inputs.benches;
    opts.command_line = joinArgs(o);
    if (isatty(fileno(stderr)) != 0)
        opts.progress = evalProgressBar(stderr);
    const auto t0 = std::chrono::steady_clock::now();
    auto result = runEvaluation(opts);
    if (!result)
        return fail("eval", result.error(), 1);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fmt::print("{}", evalSummaryText(*result, secs, o.eval.out_dir));
    return 0;
}

}  // namespace

static Registered registerEval(CLI::App& app) {
    auto o = std::make_shared<EvalCliOptions>();
    CLI::App* cmd = app.add_subcommand(
        "eval",
        "Run the paper's experiments (Fig. 12-15, Table 4) on the recorded (or synthetic) suite");
    addFramesOption(cmd, o->eval.frames, 30, 100000,
                    "Frames per run (30..100000); Fig. 14 always gets at least 300");
    addInt(cmd, "--jobs", o->eval.jobs, "Runs simulated in parallel (threads)", 1, 256);
    cmd->add_option("--bench", o->inputs.benches,
                    "Run only these suite workloads (repeatable); default: all of the suite");
    cmd->add_option("--suite", o->inputs.suite,
                    "auto (recorded when data/workloads is found, else synthetic), recorded or "
                    "synthetic")
        ->capture_default_str();
    cmd->add_option("--workloads", o->inputs.workloads,
                    "Folder of the recorded suite (suite.txt + *.jsonl; default: data/workloads "
                    "above the working directory or the executable)");
    cmd->add_option("--codec-model", o->inputs.codec_model,
                    "Periphery and background bytes of the recorded suite: lossless (the paper's "
                    "setting, §2.3), stream (our CRF 23), or auto (lossless when recorded); the "
                    "report shows the other beside it")
        ->capture_default_str();
    addHardwareOption(cmd, o->inputs.hardware, kHardwareOverrideHelp);
    cmd->add_option("--mahimahi", o->inputs.mahimahi,
                    "Mahimahi capacity traces (e.g. ../shared/data/network/*.down) to replay, "
                    "rescaled to 100 Mbps, for ffr, dfr and qvr")
        ->check(readableFile());
    cmd->add_flag("--vsync", o->eval.vsync_paced,
                  "Pace every run to the HMD's vsync: frames start at most once per refresh and "
                  "are shown at the next vsync (MTP runs to it)");
    addOutputFolderOption(cmd, o->eval.out_dir,
                          "Output folder: CSV + PNG per experiment, summary.json, report.html")
        ->required();
    return {cmd, [o]() { return runEval(*o); }};
}

QVR_REGISTER_COMMAND(50, registerEval);

}  // namespace qvr::cli
