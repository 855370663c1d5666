// Strict numeric CSV reading shared by the pose and gaze trace readers (paper §5 traces are
// untrusted files: every field checked, every error with its line).
#pragma once

#include <functional>
#include <string>
#include <string_view>
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

// csvRows, then each row in file order to `on_row` once its first column, t_ms, is checked to
// increase from the row before; the first error stops the walk. No rows at all is an error
// "no <rows_name> after the header".
Status forEachTimedRow(
    std::string_view text, std::string_view source, std::string_view header, size_t columns,
    size_t max_rows, std::string_view rows_name,
    const std::function<Status(const std::vector<double>& row, int line)>& on_row);

// Reads the file at path, at most max_bytes, and parses its text with parse(text, path).
template <typename Parse>
auto loadCsvFile(const std::string& path, size_t max_bytes, Parse parse)
    -> decltype(parse(std::string_view{}, std::string_view{})) {
    auto text = readTextFile(path, max_bytes);
    if (!text)
        return makeError(text.error());
    return parse(*text, path);
}

// Writes a whole trace's text to path, with errors that name the file.
Status writeCsvFile(const std::string& text, const std::string& path);

}  // namespace qvr::detail
