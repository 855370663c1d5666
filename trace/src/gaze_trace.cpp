// Gaze traces as CSV both ways (paper §7: one sample per eye-tracker tick).
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "csv_lines.h"
#include "qvr/core/config.h"
#include "qvr/trace/gaze_model.h"

namespace qvr {

namespace {
constexpr std::string_view kGazeHeader = "t_ms,x_deg,y_deg";
constexpr size_t kMaxRows = 50'000'000;
constexpr size_t kMaxBytes = size_t{1} << 30;
}  // namespace

std::string gazeTraceToCsv(const GazeTrace& trace) {
    std::string out(kGazeHeader);
    out += '\n';
    for (const auto& s : trace.samples)
        out += fmt::format("{:.6f},{:.6f},{:.6f}\n", s.t_ms, s.gaze.x_deg, s.gaze.y_deg);
    return out;
}

Status writeGazeCsv(const GazeTrace& trace, const std::string& path) {
    return detail::writeCsvFile(gazeTraceToCsv(trace), path);
}

Expected<GazeTrace> parseGazeCsv(std::string_view text, std::string_view source) {
    GazeTrace trace;
    const auto sample = [&](const std::vector<double>& r, int line) -> Status {
        if (std::fabs(r[1]) > 90.0 || std::fabs(r[2]) > 90.0)
            return makeError(
                fmt::format("{}:{}: gaze ({}, {}) deg beyond ±90", source, line, r[1], r[2]));
        trace.samples.push_back({r[0], Gaze{r[1], r[2]}});
        return {};
    };
    if (Status s =
            detail::forEachTimedRow(text, source, kGazeHeader, 3, kMaxRows, "samples", sample);
        !s)
        return makeError(s.error());
    return trace;
}

Expected<GazeTrace> loadGazeCsv(const std::string& path) {
    return detail::loadCsvFile(path, kMaxBytes, parseGazeCsv);
}

}  // namespace qvr
