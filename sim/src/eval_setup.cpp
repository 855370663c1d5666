// `qvr eval`'s set-up and console report (eval_setup.h).
#include "qvr/sim/eval_setup.h"

#include <algorithm>

#include <fmt/format.h>

#include "qvr/core/mahimahi.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/hardware.h"

namespace qvr {

namespace {

// `--bench hl2-l` under auto means the synthetic suite, as before recorded workloads existed.
bool namesSyntheticBench(const std::vector<std::string>& benches) {
    (void)selectSuite(SuiteKind::kSynthetic);
    for (const auto& b : benches)
        for (const auto& s : suiteBenches())
            if (b == s.name || "synthetic-" + b == s.name)
                return true;
    return false;
}

}  // namespace

Status selectEvalSuite(const EvalInputs& in) {
    // Traces are user input: a malformed one is a bad-input exit, found before any run.
    for (const auto& path : in.mahimahi)
        if (auto t = loadMahimahiTrace(path); !t)
            return makeError(t.error());
    const std::string workloads = in.workloads.empty() ? findWorkloadsDir() : in.workloads;
    const bool names_synthetic = namesSyntheticBench(in.benches);
    if (in.suite == "synthetic" || (in.suite == "auto" && (workloads.empty() || names_synthetic))) {
        (void)selectSuite(SuiteKind::kSynthetic);
        return {};
    }
    if (in.suite != "recorded" && in.suite != "auto")
        return makeError("--suite must be auto, recorded or synthetic, got '" + in.suite + "'");
    if (workloads.empty())
        return makeError(
            "--suite recorded: no data/workloads/suite.txt found above the working directory "
            "or the executable; give --workloads DIR");
    return selectSuite(SuiteKind::kRecorded, workloads);
}

Expected<CodecModel> evalCodecModel(const EvalInputs& in) {
    for (const auto& b : in.benches)
        if (auto t = makeSuiteBench(b, 1); !t)
            return makeError(t.error());
    CodecModel codec = CodecModel::kLossless;
    if (in.codec_model != "auto") {
        auto m = parseCodecModel(in.codec_model);
        if (!m)
            return makeError("--codec-model: " + m.error());
        codec = *m;
    }
    for (const auto& b : suiteBenches()) {
        if (!in.benches.empty() &&
            std::find(in.benches.begin(), in.benches.end(), b.name) == in.benches.end())
            continue;
        auto t = makeSuiteBench(b.name, 1);
        if (!t)
            return makeError(t.error());
        if (selectedSuite() == SuiteKind::kRecorded && !hasLosslessCodec(*t)) {
            if (in.codec_model == "lossless")
                return makeError("--codec-model lossless: " + b.name +
                                 " has no lossless measurements (record it again with "
                                 "scripts/record_suite.sh)");
            codec = CodecModel::kStream;
        }
    }
    if (!in.hardware.empty())
        if (auto hw = loadHardwareConfig(in.hardware, 500.0); !hw)
            return makeError(hw.error());
    return codec;
}

std::function<void(int, int)> evalProgressBar(std::FILE* out) {
    return [out](int done, int total) {
        constexpr int kWidth = 40;
        const int filled = total > 0 ? done * kWidth / total : kWidth;
        std::fprintf(out, "\r[%s%s] %d/%d runs",
                     std::string(static_cast<size_t>(filled), '#').c_str(),
                     std::string(static_cast<size_t>(kWidth - filled), ' ').c_str(), done, total);
        if (done == total)
            std::fprintf(out, "\n");
        std::fflush(out);
    };
}

std::string evalSummaryText(const EvalOutput& result, double seconds, const std::string& out_dir) {
    std::string t =
        fmt::format("{} runs in {:.1f} s; {}\n", result.runs.size(), seconds, result.plot_note);
    t += fmt::format(
        "fitted variant: acuity slope {:.5f} deg/deg, fitted once to the paper's 41% "
        "shaded-pixel reduction\n",
        result.fitted_slope);
    t += fmt::format("{:<54} {:>8} {:>9} {:>8}\n", "headline", "paper", "faithful", "fitted");
    for (const auto& h : result.headlines)
        t += fmt::format("{:<54} {:>7.2f}{} {:>8.2f}{} {:>7.2f}{}\n", h.metric, h.paper, h.unit,
                         h.ours, h.unit, h.fitted, h.unit);
    for (const auto& f : result.findings)
        t += fmt::format("[{}] {}: {}\n", f.holds ? "holds" : "FAILS", f.name, f.detail);
    t += fmt::format("report: {}/report.html\n", out_dir);
    return t;
}

}  // namespace qvr
