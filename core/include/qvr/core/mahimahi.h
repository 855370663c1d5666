// Mahimahi capacity traces (../shared/data/network/README.md): one millisecond stamp a line, each
// an opportunity for one 1500-byte packet; the trace repeats when it ends. Files are untrusted:
// this is the one reader of them (fuzz/mahimahi_fuzz.cpp), for net's link emulator and the
// simulator's trace links alike.
#pragma once

#include <cstdint>
#include <memory>
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

// Mahimahi's delivery rule over a trace rescaled to a mean rate and looped: an opportunity
// carries up to 1500 bytes, of one packet or of several; one that passes with nothing queued is
// lost; several at one stamp all carry. The trace starts with the first bytes offered. The one
// home of the rule, for net's link emulator (packets) and the simulator's trace links (layers):
// the model must lose no more of a burst's opportunities than the emulator does.
class MahimahiDelivery {
public:
    // target_bps <= 0: the trace's own rate.
    MahimahiDelivery(std::shared_ptr<const MahimahiTrace> trace, double target_bps);
    // When the last of `bytes` offered at t_ms leaves: after the bytes offered before it that
    // have not left, on the first opportunity at or after t_ms otherwise. Instants in ms on the
    // caller's clock; calls in non-decreasing t_ms. An offer at the previous departure's instant
    // (within kSameInstantMs: a caller that adds a duration back to its start can land a rounding
    // step past it) is queued behind those bytes and takes what is left of that opportunity.
    double departureMs(double t_ms, int64_t bytes);
    // The next offer starts the trace again (a new session on the link).
    void restart();
    // How long one millisecond of the trace lasts, in ms (mean / target).
    double msPerTraceMs() const { return m_ms_per_trace_ms; }

private:
    double opportunityMs(int64_t index) const;
    int64_t firstOpportunityAtOrAfter(double t_ms) const;

    std::shared_ptr<const MahimahiTrace> m_trace;
    double m_ms_per_trace_ms = 1.0;
    static constexpr double kSameInstantMs = 1e-9;
    bool m_started = false;
    double m_origin_ms = 0.0;          // the first offer: trace time 0
    double m_last_departure_ms = 0.0;  // when the last offer's bytes left
    int64_t m_index = 0;               // the opportunity being filled
    int64_t m_left_bytes = kMahimahiPacketBytes;
};

}  // namespace qvr
