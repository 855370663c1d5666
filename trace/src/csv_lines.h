// Strict numeric CSV reading shared by the pose and gaze trace readers (paper §5 traces are
// untrusted files: every field checked, every error with its line).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr::detail {

// Reads every data line after checking the header line matches `header` exactly: each field a
// finite number, exactly `columns` per row, at most max_rows rows, blank lines only at the end.
// rows[i] came from line lines[i].
Status csvRows(std::string_view text, std::string_view source, std::string_view header,
               size_t columns, size_t max_rows, std::vector<std::vector<double>>& rows,
               std::vector<int>& lines);

// Writes a whole trace's text to path, with errors that name the file.
Status writeCsvFile(const std::string& text, const std::string& path);

}  // namespace qvr::detail
