// The pieces of `qvr eval` shared by the run grid (evaluation.cpp) and its outputs
// (eval_report.cpp): the runs by name, the figures' CSV and plots, the report.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/report/html_report.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/evaluation.h"

namespace qvr::eval_detail {

inline constexpr double kDefaultMhz = 500.0;
inline const std::vector<double> kFreqsMhz = {500.0, 400.0, 300.0};
inline const std::vector<std::string> kNets = {"wifi", "lte", "5g"};
inline constexpr int kFig14Frames = 300;
// The oracle's run, the floor of Fig. 14's check: the convergence window and 100 frames after.
inline constexpr int kOracleFrames = 130;
// The paper's shaded-pixel reduction (§6.1, Fig. 13): the one figure the fitted variant is fitted
// to.
inline constexpr double kPaperPixelReduction = 0.41;

// The faithful model, or the variant whose acuity slope is fitted to the 41%.
enum class Variant { kFaithful, kFitted };
std::string_view variantSuffix(Variant v);  // "" or "-fitted"
// A design's run name in a variant: the fitted variant only changes the foveated designs.
std::string designKey(Design d, Variant v = Variant::kFaithful);

struct JobResult {
    RunSummary summary;
    std::vector<FrameRecord> frames;  // only when kept
};

// Every run of the grid, found by bench × run name × clock × network.
struct EvalRuns {
    std::vector<BenchInfo> benches;
    std::vector<WorkloadTrace> traces;        // the default codec setting, faithful acuity
    std::vector<WorkloadTrace> other_traces;  // the other codec setting, when recorded
    CodecModel codec = CodecModel::kLossless;
    CodecModel other_codec = CodecModel::kStream;
    double fitted_slope = 0.0;  // the acuity slope fitted to the 41%
    std::vector<std::string> trace_nets;
    std::map<std::string, JobResult> by_key;

    size_t size() const { return benches.size(); }
    const JobResult& job(size_t b, std::string_view name, double mhz = kDefaultMhz,
                         const std::string& net = "wifi") const;
    const RunSummary& at(size_t b, std::string_view name, double mhz = kDefaultMhz,
                         const std::string& net = "wifi") const {
        return job(b, name, mhz, net).summary;
    }
    const RunSummary& at(size_t b, Design d, Variant v = Variant::kFaithful,
                         double mhz = kDefaultMhz, const std::string& net = "wifi") const {
        return at(b, designKey(d, v), mhz, net);
    }
};
std::string runKey(const std::string& bench, std::string_view name, double mhz,
                   const std::string& net);

double mean(const std::vector<double>& v);
std::string fmtNum(double v, int prec = 2);
std::string fmtCell(double v, int prec = 2);

// The outputs: CSV files and plots, listed in `files` as written.
class Outputs {
public:
    explicit Outputs(const std::filesystem::path& dir);
    Status csv(const std::string& name, const std::string& text);
    void plot(const std::string& name, const std::string& title, const std::string& body);
    const std::filesystem::path& dir() const { return m_dir; }
    std::vector<std::string>& files() { return m_files; }
    bool has(const std::string& name) const;
    std::string plotNote() const { return m_plotter.note(); }

private:
    std::filesystem::path m_dir;
    report::Plotter m_plotter;
    std::vector<std::string> m_files;
};

// The figures' CSV and plots (Fig. 12–15, Table 4, Mahimahi); each returns its CSV text.
Expected<std::string> writeFig12(const EvalRuns& runs, Outputs& out);
Expected<std::string> writeFig13(const EvalRuns& runs, Outputs& out);
Status writeFig14(const EvalRuns& runs, Outputs& out);
Expected<std::string> writeTable4(const EvalRuns& runs, Outputs& out);
Expected<std::string> writeFig15(const EvalRuns& runs, Outputs& out);
Status writeMahimahi(const EvalRuns& runs, Outputs& out);

// The Fig. 14 balance check on every bench (its CSV too).
Expected<Finding> fig14Finding(const EvalRuns& runs, Outputs& out);

struct ReportInputs {
    const EvalOptions& options;
    const EvalRuns& runs;
    const EvalOutput& output;
    std::string fig12, fig13, t4, f15;
};
Status writeReport(const ReportInputs& in, Outputs& out);

}  // namespace qvr::eval_detail
