// `qvr eval`: the paper's evaluation (§6: Fig. 12–15, Table 4) over the Table 3 suite, with
// CSV, gnuplot figures, summary.json and report.html in one folder.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.h"
#include "options.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/evaluation.h"
#include "qvr/sim/network.h"

namespace qvr::cli {

namespace {

struct EvalCliOptions {
    int frames = 400;
    int jobs = 2;
    std::string out;
    std::vector<std::string> mahimahi;
    std::vector<std::string> benches;
    std::string hardware;
    std::string suite = "auto";  // auto: recorded when data/workloads is found, else synthetic
    std::string workloads;
    std::string codec_model = "auto";  // auto: lossless when every recorded trace has it
    bool vsync = false;
};

std::string joinArgs(const EvalCliOptions& o) {
    std::string s =
        fmt::format("qvr eval --suite {} --codec-model {} --frames {} --jobs {} --out {}", o.suite,
                    o.codec_model, o.frames, o.jobs, o.out);
    if (o.vsync)
        s += " --vsync";
    if (!o.mahimahi.empty())
        s += " --mahimahi";
    for (const auto& m : o.mahimahi)
        s += " " + m;
    return s;
}

int runEval(const EvalCliOptions& o) {
    if (o.frames < 30 || o.frames > 100'000) {
        std::fprintf(stderr, "qvr eval: --frames must be within 30..100000, got %d\n", o.frames);
        return 2;
    }
    if (o.jobs < 1 || o.jobs > 256) {
        std::fprintf(stderr, "qvr eval: --jobs must be within 1..256, got %d\n", o.jobs);
        return 2;
    }
    // Traces are user input: a malformed one is a bad-input exit, found before any run.
    for (const auto& path : o.mahimahi) {
        auto t = loadMahimahiTrace(path);
        if (!t) {
            std::fprintf(stderr, "qvr eval: %s\n", t.error().c_str());
            return 2;
        }
    }
    // The suite: the recorded OpenArena workloads unless asked otherwise or not found.
    std::string workloads = o.workloads.empty() ? findWorkloadsDir() : o.workloads;
    // `--bench hl2-l` under auto means the synthetic suite, as before recorded workloads existed.
    bool names_synthetic = false;
    (void)selectSuite(SuiteKind::kSynthetic);
    for (const auto& b : o.benches) {
        for (const auto& s : suiteBenches())
            names_synthetic = names_synthetic || b == s.name || "synthetic-" + b == s.name;
    }
    if (o.suite == "synthetic" || (o.suite == "auto" && (workloads.empty() || names_synthetic))) {
        (void)selectSuite(SuiteKind::kSynthetic);
    } else if (o.suite == "recorded" || o.suite == "auto") {
        if (workloads.empty()) {
            std::fprintf(stderr,
                         "qvr eval: --suite recorded: no data/workloads/suite.txt found "
                         "above the working directory or the executable; give "
                         "--workloads DIR\n");
            return 2;
        }
        if (Status s = selectSuite(SuiteKind::kRecorded, workloads); !s) {
            std::fprintf(stderr, "qvr eval: %s\n", s.error().c_str());
            return 2;
        }
    } else {
        std::fprintf(stderr, "qvr eval: --suite must be auto, recorded or synthetic, got '%s'\n",
                     o.suite.c_str());
        return 2;
    }
    fmt::print("suite: {}\n", suiteBenchNamesList());
    for (const auto& b : o.benches) {
        auto t = makeSuiteBench(b, 1);
        if (!t) {
            std::fprintf(stderr, "qvr eval: %s\n", t.error().c_str());
            return 2;
        }
    }
    // The codec setting: the paper's (lossless, §2.3) when the suite recorded it.
    CodecModel codec = CodecModel::kLossless;
    if (o.codec_model != "auto") {
        auto m = parseCodecModel(o.codec_model);
        if (!m) {
            std::fprintf(stderr, "qvr eval: --codec-model: %s\n", m.error().c_str());
            return 2;
        }
        codec = *m;
    }
    for (const auto& b : suiteBenches()) {
        if (!o.benches.empty() &&
            std::find(o.benches.begin(), o.benches.end(), b.name) == o.benches.end())
            continue;
        auto t = makeSuiteBench(b.name, 1);
        if (!t) {
            std::fprintf(stderr, "qvr eval: %s\n", t.error().c_str());
            return 2;
        }
        if (selectedSuite() == SuiteKind::kRecorded && !hasLosslessCodec(*t)) {
            if (o.codec_model == "lossless") {
                std::fprintf(stderr,
                             "qvr eval: --codec-model lossless: %s has no lossless measurements "
                             "(record it again with scripts/record_suite.sh)\n",
                             b.name.c_str());
                return 2;
            }
            codec = CodecModel::kStream;
        }
    }
    if (!o.hardware.empty()) {
        auto hw = loadHardwareConfig(o.hardware, 500.0);
        if (!hw) {
            std::fprintf(stderr, "qvr eval: %s\n", hw.error().c_str());
            return 2;
        }
    }
    EvalOptions opts;
    opts.hardware_path = o.hardware;
    opts.codec_model = codec;
    opts.mahimahi_traces = o.mahimahi;
    opts.benches = o.benches;
    opts.frames = o.frames;
    opts.jobs = o.jobs;
    opts.vsync_paced = o.vsync;
    opts.out_dir = o.out;
    opts.command_line = joinArgs(o);
    const bool tty = isatty(fileno(stderr)) != 0;
    if (tty) {
        opts.progress = [](int done, int total) {
            constexpr int kWidth = 40;
            const int filled = total > 0 ? done * kWidth / total : kWidth;
            std::fprintf(stderr, "\r[%s%s] %d/%d runs",
                         std::string(static_cast<size_t>(filled), '#').c_str(),
                         std::string(static_cast<size_t>(kWidth - filled), ' ').c_str(), done,
                         total);
            if (done == total)
                std::fprintf(stderr, "\n");
            std::fflush(stderr);
        };
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto result = runEvaluation(opts);
    if (!result) {
        std::fprintf(stderr, "qvr eval: %s\n", result.error().c_str());
        return 1;
    }
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fmt::print("{} runs in {:.1f} s; {}\n", result->runs.size(), secs, result->plot_note);
    fmt::print(
        "fitted variant: acuity slope {:.5f} deg/deg, fitted once to the paper's 41% "
        "shaded-pixel reduction\n",
        result->fitted_slope);
    fmt::print("{:<54} {:>8} {:>9} {:>8}\n", "headline", "paper", "faithful", "fitted");
    for (const auto& h : result->headlines)
        fmt::print("{:<54} {:>7.2f}{} {:>8.2f}{} {:>7.2f}{}\n", h.metric, h.paper, h.unit, h.ours,
                   h.unit, h.fitted, h.unit);
    for (const auto& f : result->findings)
        fmt::print("[{}] {}: {}\n", f.holds ? "holds" : "FAILS", f.name, f.detail);
    fmt::print("report: {}/report.html\n", o.out);
    return 0;
}

}  // namespace

static Registered registerEval(CLI::App& app) {
    auto o = std::make_shared<EvalCliOptions>();
    CLI::App* cmd = app.add_subcommand(
        "eval",
        "Run the paper's experiments (Fig. 12-15, Table 4) on the recorded (or synthetic) suite");
    addFramesOption(cmd, o->frames, 30, 100000,
                    "Frames per run (30..100000); Fig. 14 always gets at least 300");
    cmd->add_option("--jobs", o->jobs, "Runs simulated in parallel (threads)")
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    cmd->add_option("--bench", o->benches,
                    "Run only these suite workloads (repeatable); default: all of the suite");
    cmd->add_option("--suite", o->suite,
                    "auto (recorded when data/workloads is found, else synthetic), recorded or "
                    "synthetic")
        ->capture_default_str();
    cmd->add_option("--workloads", o->workloads,
                    "Folder of the recorded suite (suite.txt + *.jsonl; default: data/workloads "
                    "above the working directory or the executable)");
    cmd->add_option("--codec-model", o->codec_model,
                    "Periphery and background bytes of the recorded suite: lossless (the paper's "
                    "setting, §2.3), stream (our CRF 23), or auto (lossless when recorded); the "
                    "report shows the other beside it")
        ->capture_default_str();
    cmd->add_option("--hardware", o->hardware,
                    "TOML file overriding the modelled hardware's constants (docs/MODEL.md)")
        ->check(readableFile());
    cmd->add_option("--mahimahi", o->mahimahi,
                    "Mahimahi capacity traces (e.g. ../shared/data/network/*.down) to replay, "
                    "rescaled to 100 Mbps, for ffr, dfr and qvr")
        ->check(readableFile());
    cmd->add_flag("--vsync", o->vsync,
                  "Pace every run to the HMD's vsync: frames start at most once per refresh and "
                  "are shown at the next vsync (MTP runs to it)");
    cmd->add_option("--out", o->out,
                    "Output folder: CSV + PNG per experiment, summary.json, report.html")
        ->required()
        ->check(outputFolder());
    return {cmd, [o]() { return runEval(*o); }};
}

QVR_REGISTER_COMMAND(50, registerEval);

}  // namespace qvr::cli
