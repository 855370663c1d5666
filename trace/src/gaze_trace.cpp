// Gaze traces as CSV both ways (paper §7: one sample per eye-tracker tick).
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "csv_lines.h"
#include "qvr/core/config.h"
#include "qvr/trace/gaze_model.h"

namespace qvr {

namespace {
constexpr detail::TimedCsvFormat kGazeCsv{
    .header = "t_ms,x_deg,y_deg", .columns = 3, .max_rows = 50'000'000, .rows_name = "samples"};
}  // namespace

std::string gazeTraceToCsv(const GazeTrace& trace) {
    return detail::timedCsvText(kGazeCsv, trace.samples, [](const GazeSample& s) {
        return fmt::format("{:.6f},{:.6f},{:.6f}\n", s.t_ms, s.gaze.x_deg, s.gaze.y_deg);
    });
}

Status writeGazeCsv(const GazeTrace& trace, const std::string& path) {
    return detail::writeCsvFile(gazeTraceToCsv(trace), path);
}

Expected<GazeTrace> parseGazeCsv(std::string_view text, std::string_view source) {
    return detail::parseTimedCsv<GazeTrace>(
        text, source, kGazeCsv,
        [&](const std::vector<double>& r, int line) -> Expected<GazeSample> {
            if (std::fabs(r[1]) > 90.0 || std::fabs(r[2]) > 90.0)
                return makeError(
                    fmt::format("{}:{}: gaze ({}, {}) deg beyond ±90", source, line, r[1], r[2]));
            return GazeSample{r[0], Gaze{r[1], r[2]}};
        });
}

Expected<GazeTrace> loadGazeCsv(const std::string& path) {
    return detail::loadCsvFile(path, kGazeCsv, parseGazeCsv);
}

}  // namespace qvr
