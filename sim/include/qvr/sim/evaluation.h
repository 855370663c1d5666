// `qvr eval`: the paper's experiments (§6: Fig. 12–15, Table 4) over the benchmark suite, each
// written as CSV plus a gnuplot figure, gathered in report.html with the paper's headline
// figures beside ours, and every run in summary.json.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/sim/simulator.h"

namespace qvr {

struct EvalOptions {
    int frames = 400;
    int jobs = 2;
    std::string out_dir;
    // Mahimahi capacity traces to replay (rescaled to 100 Mbps) for Q-VR, DFR and FFR; none
    // by default.
    std::vector<std::string> mahimahi_traces;
    // TOML overrides of the hardware defaults (parseHardwareConfig); empty keeps them.
    std::string hardware_path;
    // Which recorded codec setting the suite's bytes come from (docs/MODEL.md, "Codec"); every
    // design at the default point also runs with the other one when the suite recorded both.
    CodecModel codec_model = CodecModel::kLossless;
    // A subset of the suite by name; empty runs all seven.
    std::vector<std::string> benches;
    std::string command_line;                           // recorded in the report
    std::function<void(int done, int total)> progress;  // called from worker threads, serialised
};

// One of the paper's qualitative findings checked on our runs.
struct Finding {
    std::string name;
    bool holds = false;
    std::string detail;
};

// The paper's headline numbers (abstract, §6) and ours.
struct Headline {
    std::string metric;
    double paper = 0.0;
    double ours = 0.0;
    std::string unit;  // "x" or "%"
};

struct EvalOutput {
    std::vector<RunSummary> runs;
    std::vector<Headline> headlines;
    std::vector<Finding> findings;
    std::vector<std::string> files;  // written, relative to out_dir
    std::string plot_note;           // how plots were made, or why not
};

Expected<EvalOutput> runEvaluation(const EvalOptions& options);

// Shared with `qvr sim`.
Status writeSummaryJson(const std::string& path, const std::vector<RunSummary>& runs);
Status writeFramesCsv(const std::string& path, const std::vector<FrameRecord>& frames);

}  // namespace qvr
