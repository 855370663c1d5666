// Mahimahi trace reader: a strict line grammar, checked before anything is stored.
#include "qvr/core/mahimahi.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "qvr/core/check.h"

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

MahimahiDelivery::MahimahiDelivery(std::shared_ptr<const MahimahiTrace> trace, double target_bps)
    : m_trace(std::move(trace)) {
    QVR_CHECK(m_trace && m_trace->period_ms > 0 && !m_trace->stamps_ms.empty());
    // Dividing every stamp by target / mean compresses time so the mean becomes the target.
    if (target_bps > 0.0)
        m_ms_per_trace_ms = m_trace->meanBps() / target_bps;
}

void MahimahiDelivery::restart() {
    m_started = false;
    m_last_departure_ms = 0.0;
    m_index = 0;
    m_left_bytes = kMahimahiPacketBytes;
}

double MahimahiDelivery::opportunityMs(int64_t index) const {
    const auto& stamps = m_trace->stamps_ms;
    const int64_t n = static_cast<int64_t>(stamps.size());
    const int64_t loop = index / n;
    const double ms = static_cast<double>(stamps[static_cast<size_t>(index % n)]) +
                      static_cast<double>(loop) * static_cast<double>(m_trace->period_ms);
    return m_origin_ms + ms * m_ms_per_trace_ms;
}

int64_t MahimahiDelivery::firstOpportunityAtOrAfter(double t_ms) const {
    const auto& stamps = m_trace->stamps_ms;
    const int64_t n = static_cast<int64_t>(stamps.size());
    const double period = static_cast<double>(m_trace->period_ms);
    const double trace_ms = std::max(0.0, (t_ms - m_origin_ms) / m_ms_per_trace_ms);
    const int64_t loop = static_cast<int64_t>(std::floor(trace_ms / period));
    // Within the loop, the first stamp whose time is not before t; rounding can put t a hair
    // past the loop's last stamp, in which case the next loop's first stamp is it.
    const double within = trace_ms - static_cast<double>(loop) * period;
    const auto it = std::lower_bound(stamps.begin(), stamps.end(), within, [](int64_t s, double v) {
        return static_cast<double>(s) < v;
    });
    int64_t index = loop * n + static_cast<int64_t>(it - stamps.begin());
    while (opportunityMs(index) < t_ms)
        ++index;
    return index;
}

double MahimahiDelivery::departureMs(double t_ms, int64_t bytes) {
    if (!m_started) {
        m_started = true;
        m_origin_ms = t_ms;
        m_index = 0;
        m_left_bytes = kMahimahiPacketBytes;
    }
    if (t_ms <= m_last_departure_ms + kSameInstantMs)
        t_ms = std::min(t_ms, m_last_departure_ms);  // queued behind the bytes that just left
    if (opportunityMs(m_index) < t_ms) {
        // Opportunities that passed with nothing queued are lost, as in Mahimahi.
        m_index = firstOpportunityAtOrAfter(t_ms);
        m_left_bytes = kMahimahiPacketBytes;
    }
    int64_t remaining = std::max<int64_t>(bytes, 0);
    // Whole loops at once, so a payload of many loops costs O(trace), not O(packets).
    const int64_t n = m_trace->packets();
    const int64_t loop_bytes = n * kMahimahiPacketBytes;
    if (remaining > m_left_bytes + loop_bytes) {
        const int64_t loops = (remaining - m_left_bytes) / loop_bytes;
        m_index += loops * n;
        remaining -= loops * loop_bytes;
    }
    while (true) {
        const int64_t take = std::min(remaining, m_left_bytes);
        remaining -= take;
        m_left_bytes -= take;
        const double t = opportunityMs(m_index);
        if (m_left_bytes == 0) {
            ++m_index;
            m_left_bytes = kMahimahiPacketBytes;
        }
        if (remaining == 0) {
            m_last_departure_ms = t;
            return t;
        }
    }
}

}  // namespace qvr
