// Mahimahi capacity traces (../shared/data/network/README.md): one millisecond stamp a line, each
// an opportunity for one 1500-byte packet; the trace repeats when it ends. Files are untrusted:
// this is the one reader of them (fuzz/mahimahi_fuzz.cpp), for net's link emulator and the
// simulator's trace links alike.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr {

inline constexpr int64_t kMahimahiPacketBytes = 1500;
inline constexpr int64_t kMaxMahimahiLines = 20'000'000;
inline constexpr int64_t kMaxMahimahiStampMs = 1'000'000'000;  // 11.6 days
inline constexpr int64_t kMaxMahimahiFileBytes = 256 << 20;

struct MahimahiTrace {
    std::string source;
    std::vector<int64_t> stamps_ms;  // non-decreasing, as read
    int64_t period_ms = 0;           // the last stamp: the length of one loop (Mahimahi's rule)
    int64_t packets() const { return static_cast<int64_t>(stamps_ms.size()); }
    // packets · 1500 B · 8 / period.
    double meanBps() const;
};

// Grammar: lines of 1–10 decimal digits, value ≤ kMaxMahimahiStampMs, each ≥ the one before;
// an optional CR before LF; blank lines skipped; nothing else (no signs, spaces or comments).
// At least one stamp, last stamp > 0, at most kMaxMahimahiLines stamps. Errors name the line.
Expected<MahimahiTrace> parseMahimahiTrace(std::string_view text, const std::string& source);
// Refuses files over kMaxMahimahiFileBytes before reading them.
Expected<MahimahiTrace> loadMahimahiTrace(const std::string& path);

}  // namespace qvr
