// Mahimahi trace reader: a strict line grammar, checked before anything is stored.
#include "qvr/core/mahimahi.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace qvr {

double MahimahiTrace::meanBps() const {
    if (period_ms <= 0) {
        return 0.0;
    }
    return static_cast<double>(packets()) * kMahimahiPacketBytes * 8.0 /
           (static_cast<double>(period_ms) / 1000.0);
}

Expected<MahimahiTrace> parseMahimahiTrace(std::string_view text, const std::string& source) {
    MahimahiTrace trace;
    trace.source = source;
    int64_t line_no = 0;
    size_t pos = 0;
    while (pos < text.size()) {
        ++line_no;
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) {
            end = text.size();
        }
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        if (!line.empty() && line.back() == '\r') {
            line.remove_suffix(1);
        }
        if (line.empty()) {
            continue;
        }
        const std::string where = source + ":" + std::to_string(line_no) + ": ";
        if (line.size() > 10) {
            return makeError(where + "timestamp too long (more than 10 digits)");
        }
        int64_t value = 0;
        for (char c : line) {
            if (c < '0' || c > '9') {
                return makeError(
                    where +
                    "expected a non-negative integer millisecond timestamp (digits only), got '" +
                    std::string(line) + "'");
            }
            value = value * 10 + (c - '0');
        }
        if (value > kMaxMahimahiStampMs) {
            return makeError(where + "timestamp " + std::to_string(value) + " ms exceeds " +
                             std::to_string(kMaxMahimahiStampMs));
        }
        if (!trace.stamps_ms.empty() && value < trace.stamps_ms.back()) {
            return makeError(where + "timestamp " + std::to_string(value) +
                             " ms goes back in time (previous " +
                             std::to_string(trace.stamps_ms.back()) + " ms)");
        }
        if (trace.packets() >= kMaxMahimahiLines) {
            return makeError(where + "more than " + std::to_string(kMaxMahimahiLines) +
                             " delivery opportunities");
        }
        trace.stamps_ms.push_back(value);
    }
    if (trace.stamps_ms.empty()) {
        return makeError(source + ": no delivery opportunities in the trace");
    }
    trace.period_ms = trace.stamps_ms.back();
    if (trace.period_ms <= 0) {
        return makeError(source + ": the last timestamp must be > 0 ms (it is the loop length)");
    }
    return trace;
}

Expected<MahimahiTrace> loadMahimahiTrace(const std::string& path) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) {
        return makeError(path + ": cannot open Mahimahi trace: " + ec.message());
    }
    if (size > static_cast<uintmax_t>(kMaxMahimahiFileBytes)) {
        return makeError(path + ": Mahimahi trace of " + std::to_string(size) +
                         " bytes exceeds the limit of " + std::to_string(kMaxMahimahiFileBytes));
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        return makeError(path + ": cannot open Mahimahi trace");
    }
    std::ostringstream text;
    text << in.rdbuf();
    return parseMahimahiTrace(text.str(), path);
}

}  // namespace qvr
