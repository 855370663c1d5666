// `qvr eval`'s set-up and console report as typed functions: the suite chosen from the command
// line's names, every user input checked before any run (a failure is bad input), the codec
// setting resolved, and the lines printed once runEvaluation (evaluation.h) is done.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/sim/evaluation.h"

namespace qvr {

// What the command line asks of the evaluation's inputs.
struct EvalInputs {
    std::string suite = "auto";  // auto: recorded when data/workloads is found, else synthetic
    std::string workloads;       // the recorded suite's folder; empty: findWorkloadsDir()
    std::vector<std::string> benches;   // a subset of the suite by name; empty: all of it
    std::vector<std::string> mahimahi;  // Mahimahi trace files
    std::string codec_model = "auto";   // auto: lossless when every recorded trace has it
    std::string hardware;               // TOML overrides; empty: none
};

// Checks the Mahimahi traces and selects the suite (selectSuite): the recorded one unless
// asked otherwise, not found, or named by a synthetic bench under "auto".
Status selectEvalSuite(const EvalInputs& inputs);

// After selectEvalSuite: checks the benches and the hardware file, and resolves the codec
// setting — the paper's lossless one (§2.3) when the suite recorded it, stream otherwise.
Expected<CodecModel> evalCodecModel(const EvalInputs& inputs);

// A progress bar of `done` of `total` runs on `out`, redrawn in place (for a terminal).
std::function<void(int done, int total)> evalProgressBar(std::FILE* out);

// The lines `qvr eval` prints when done: runs and time, the fitted slope, the headline table,
// the findings and where the report is.
std::string evalSummaryText(const EvalOutput& result, double seconds, const std::string& out_dir);

}  // namespace qvr
