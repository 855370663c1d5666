// Strict numeric CSV for pose and gaze traces (paper §5).
#include "csv_lines.h"

#include <charconv>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

namespace qvr::detail {

Status csvRows(std::string_view text, std::string_view source, std::string_view header,
               size_t columns, size_t max_rows, std::vector<std::vector<double>>& rows,
               std::vector<int>& lines) {
    rows.clear();
    lines.clear();
    int line = 0;
    bool blank_seen = false;
    size_t pos = 0;
    while (pos < text.size()) {
        const size_t nl = text.find('\n', pos);
        std::string_view l = text.substr(pos, nl == std::string_view::npos ? text.npos : nl - pos);
        pos = nl == std::string_view::npos ? text.size() : nl + 1;
        ++line;
        if (!l.empty() && l.back() == '\r')
            l.remove_suffix(1);
        if (line == 1) {
            if (l != header)
                return makeError(fmt::format("{}:1: header must be '{}', found '{}'", source,
                                             header, l.substr(0, 80)));
            continue;
        }
        if (l.empty()) {
            blank_seen = true;
            continue;
        }
        if (blank_seen)
            return makeError(fmt::format("{}:{}: data after a blank line", source, line));
        if (rows.size() >= max_rows)
            return makeError(fmt::format("{}:{}: more than {} rows", source, line, max_rows));
        std::vector<double> fields;
        fields.reserve(columns);
        size_t start = 0;
        for (;;) {
            const size_t comma = l.find(',', start);
            const std::string_view f =
                l.substr(start, comma == std::string_view::npos ? l.npos : comma - start);
            double v = 0;
            const char* end = f.data() + f.size();
            auto r = std::from_chars(f.data(), end, v);
            if (f.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v))
                return makeError(fmt::format("{}:{}: field {} '{}' is not a finite number", source,
                                             line, fields.size() + 1, f.substr(0, 40)));
            fields.push_back(v);
            if (fields.size() > columns)
                break;
            if (comma == std::string_view::npos)
                break;
            start = comma + 1;
        }
        if (fields.size() > columns)
            return makeError(
                fmt::format("{}:{}: more than {} fields ({})", source, line, columns, header));
        if (fields.size() < columns)
            return makeError(fmt::format("{}:{}: only {} fields, expected {} ({})", source, line,
                                         fields.size(), columns, header));
        rows.push_back(std::move(fields));
        lines.push_back(line);
    }
    if (line == 0)
        return makeError(fmt::format("{}: empty file (expected header '{}')", source, header));
    return Status::success();
}

Status forEachTimedRow(
    std::string_view text, std::string_view source, const TimedCsvFormat& format,
    const std::function<Status(const std::vector<double>& row, int line)>& on_row) {
    std::vector<std::vector<double>> rows;
    std::vector<int> lines;
    if (Status s =
            csvRows(text, source, format.header, format.columns, format.max_rows, rows, lines);
        !s)
        return s;
    if (rows.empty())
        return makeError(fmt::format("{}: no {} after the header", source, format.rows_name));
    for (size_t i = 0; i < rows.size(); ++i) {
        if (i > 0 && !(rows[i][0] > rows[i - 1][0]))
            return makeError(
                fmt::format("{}:{}: t_ms {} does not increase", source, lines[i], rows[i][0]));
        if (Status s = on_row(rows[i], lines[i]); !s)
            return s;
    }
    return {};
}

Status writeCsvFile(const std::string& text, const std::string& path) {
    std::ofstream f(path, std::ios::binary);
    if (!f)
        return makeError(fmt::format("cannot write '{}'", path));
    f.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!f)
        return makeError(fmt::format("error writing '{}'", path));
    return Status::success();
}

}  // namespace qvr::detail
