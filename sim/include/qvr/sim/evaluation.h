// `qvr eval`: the paper's experiments (§6: Fig. 12–15, Table 4) over the benchmark suite, each
// written as CSV plus a gnuplot figure, gathered in report.html with the paper's headline
// figures beside ours, and every run in summary.json.
#pragma once

#include <cstdint>
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
    // Every run paced to the HMD's vsync (SimConfig::vsync_paced).
    bool vsync_paced = false;
    std::string command_line;                           // recorded in the report
    std::function<void(int done, int total)> progress;  // called from worker threads, serialised
};

// One of the paper's qualitative findings checked on our runs.
struct Finding {
    std::string name;
    bool holds = false;
    std::string detail;
};

// The paper's headline numbers (abstract, §6) and ours: the faithful model's and the fitted
// variant's (acuity slope fitted to the 41% shaded-pixel reduction; every other figure is a
// prediction).
struct Headline {
    std::string metric;
    double paper = 0.0;
    double ours = 0.0;    // faithful
    double fitted = 0.0;  // the fitted variant
    std::string unit;     // "x" or "%"
    // The fitted variant's per-frame quantities behind the figure (suite means).
    std::string mechanism;
    // More than 25% from the paper in the fitted column.
    bool fittedFar() const;
};

struct EvalOutput {
    std::vector<RunSummary> runs;
    std::vector<Headline> headlines;
    std::vector<Finding> findings;
    std::vector<std::string> files;  // written, relative to out_dir
    std::string plot_note;           // how plots were made, or why not
    double fitted_slope = 0.0;       // the fitted variant's acuity slope (deg/deg)
};

Expected<EvalOutput> runEvaluation(const EvalOptions& options);

// The noise seed of a bench's link: from the bench's and the network's names only, so a bench
// sees the same link noise run alone or in the suite.
uint64_t benchLinkSeed(const std::string& bench, const std::string& net);

// The acuity slope m whose shaded-pixel reduction `reduction_at(m)` equals `target`, searched in
// log m over [lo, hi] (the reduction grows with m). Stops within `tolerance` of the target; the
// last slope tried is the answer, so the caller's last evaluation is at the returned slope.
double fitAcuitySlope(const std::function<double(double)>& reduction_at, double target, double lo,
                      double hi, double tolerance);

// Shared with `qvr sim`.
Status writeSummaryJson(const std::string& path, const std::vector<RunSummary>& runs);
Status writeFramesCsv(const std::string& path, const std::vector<FrameRecord>& frames);

}  // namespace qvr
