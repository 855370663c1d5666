// Strict numeric CSV reading shared by the pose and gaze trace readers (paper §5 traces are
// untrusted files: every field checked, every error with its line).
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "qvr/core/config.h"
#include "qvr/core/expected.h"

namespace qvr::detail {

// Reads every data line after checking the header line matches `header` exactly: each field a
// finite number, exactly `columns` per row, at most max_rows rows, blank lines only at the end.
// rows[i] came from line lines[i].
Status csvRows(std::string_view text, std::string_view source, std::string_view header,
               size_t columns, size_t max_rows, std::vector<std::vector<double>>& rows,
               std::vector<int>& lines);

// One trace file format: a header line, then one row per sample, t_ms first and increasing.
struct TimedCsvFormat {
    std::string_view header;             // the exact first line
    size_t columns = 0;                  // fields per row, t_ms included
    size_t max_rows = 0;                 // rows a file may hold
    size_t max_bytes = size_t{1} << 30;  // bytes a file may hold
    std::string_view rows_name;          // what a row is, for "no <rows_name> after the header"
};

// csvRows, then each row in file order to `on_row` once its first column, t_ms, is checked to
// increase from the row before; the first error stops the walk. No rows at all is an error
// "no <rows_name> after the header".
Status forEachTimedRow(
    std::string_view text, std::string_view source, const TimedCsvFormat& format,
    const std::function<Status(const std::vector<double>& row, int line)>& on_row);

// A trace read by forEachTimedRow: to_sample(row, line), an Expected sample, gives each of
// trace.samples in file order; its first error is the trace's.
template <typename Trace, typename ToSample>
Expected<Trace> parseTimedCsv(std::string_view text, std::string_view source,
                              const TimedCsvFormat& format, ToSample to_sample) {
    Trace trace;
    const Status s =
        forEachTimedRow(text, source, format, [&](const std::vector<double>& row, int line) {
            auto sample = to_sample(row, line);
            if (!sample)
                return Status(makeError(sample.error()));
            trace.samples.push_back(std::move(*sample));
            return Status::success();
        });
    if (!s)
        return makeError(s.error());
    return trace;
}

// A trace's text: the format's header line, then format_row(sample) (a line, '\n' included)
// for each sample in order.
template <typename Samples, typename FormatRow>
std::string timedCsvText(const TimedCsvFormat& format, const Samples& samples,
                         FormatRow format_row) {
    std::string out(format.header);
    out += '\n';
    for (const auto& sample : samples)
        out += format_row(sample);
    return out;
}

// Reads the file at path, at most the format's max_bytes, and parses its text with
// parse(text, path).
template <typename Parse>
auto loadCsvFile(const std::string& path, const TimedCsvFormat& format, Parse parse)
    -> decltype(parse(std::string_view{}, std::string_view{})) {
    auto text = readTextFile(path, format.max_bytes);
    if (!text)
        return makeError(text.error());
    return parse(*text, path);
}

// Writes a whole trace's text to path, with errors that name the file.
Status writeCsvFile(const std::string& text, const std::string& path);

}  // namespace qvr::detail
