// Downlink models (paper §5, Table 2) and the Table 1 calibration; sources in docs/MODEL.md.
#include "qvr/sim/network.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

namespace qvr {

const std::vector<Table1Row>& table1Rows() {
    static const std::vector<Table1Row> rows = {
        {"Foveated3D", 646e3, 38.0}, {"Viking", 530e3, 31.0},     {"Nature", 482e3, 28.0},
        {"Sponza", 537e3, 31.0},     {"San Miguel", 572e3, 33.0},
    };
    return rows;
}

double calibratedLinkEfficiency() {
    // Least squares on T_i = bits_i · k with k = 1/(η·C): k = Σ bits·T / Σ bits².
    constexpr double kWifiNominalBps = 200e6;
    double num = 0.0, den = 0.0;
    for (const auto& r : table1Rows()) {
        const double bits = r.background_bytes * 8.0;
        const double t_s = r.t_remote_ms * 1e-3;
        num += bits * t_s;
        den += bits * bits;
    }
    const double goodput_bps = den / num;
    return goodput_bps / kWifiNominalBps;
}

double RadioPower::energyPerBitNj(double goodput_bps) const {
    if (goodput_bps <= 0.0)
        return 0.0;
    // mW per Mbps is nJ per bit; β mW over R bits/s is β·1e6/R nJ per bit.
    return alpha_mw_per_mbps + beta_mw * 1e6 / goodput_bps;
}

NoisyLink::NoisyLink(std::string name, double nominal_bps, double efficiency, double snr_db,
                     RadioPower radio, uint64_t seed)
    : m_name(std::move(name)),
      m_nominal_bps(nominal_bps),
      m_efficiency(efficiency),
      m_sigma(std::isfinite(snr_db) ? std::pow(10.0, -snr_db / 20.0) : 0.0),
      m_radio(radio),
      m_rng(seed) {
    QVR_CHECK(nominal_bps > 0.0 && efficiency > 0.0 && efficiency <= 1.0);
}

LinkTransfer NoisyLink::transfer(double /*start_ms*/, double payload_bytes) {
    // The noise is per sample (§5: white noise in the channel); a frame's goodput averages it over
    // the frame's packets, so its spread is σ/√packets. One N(0,1) draw scaled so is that mean
    // exactly in distribution.
    double factor = 1.0;
    if (m_sigma > 0.0)
        factor = std::max(0.05, 1.0 + noiseSigmaOver(payload_bytes) * m_normal(m_rng));
    const double goodput_bps = meanGoodputBps() * factor;
    if (payload_bytes <= 0.0)
        return {0.0, goodput_bps};
    return {payload_bytes * 8.0 / goodput_bps * 1e3, goodput_bps};
}

double NoisyLink::packetsOf(double payload_bytes) const {
    return std::max(1.0, std::ceil(payload_bytes / (m_efficiency * kMahimahiPacketBytes)));
}

double NoisyLink::noiseSigmaOver(double payload_bytes) const {
    return m_sigma / std::sqrt(packetsOf(payload_bytes));
}

double MahimahiTrace::meanBps() const {
    if (period_ms <= 0.0)
        return 0.0;
    return static_cast<double>(opportunities_ms.size()) * kMahimahiPacketBytes * 8.0 /
           (period_ms * 1e-3);
}

Expected<MahimahiTrace> parseMahimahiTrace(std::string_view text, const std::string& source) {
    MahimahiTrace trace;
    int64_t line_no = 0;
    size_t pos = 0;
    double previous = -1.0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos)
            end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_no;
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
            line.remove_suffix(1);
        while (!line.empty() && (line.front() == ' ' || line.front() == '\t'))
            line.remove_prefix(1);
        if (line.empty())
            continue;
        if (line_no > kMaxMahimahiLines)
            return makeError(fmt::format("{}: more than {} lines", source, kMaxMahimahiLines));
        uint64_t value = 0;
        const auto [ptr, ec] = std::from_chars(line.data(), line.data() + line.size(), value);
        if (ec != std::errc() || ptr != line.data() + line.size())
            return makeError(
                fmt::format("{}:{}: expected a non-negative integer millisecond stamp, got '{}'",
                            source, line_no, std::string(line.substr(0, 40))));
        if (value > 1'000'000'000ULL)
            return makeError(
                fmt::format("{}:{}: stamp {} ms is beyond 1e9", source, line_no, value));
        const double ms = static_cast<double>(value);
        if (ms < previous)
            return makeError(fmt::format("{}:{}: stamp {} is earlier than the previous {}", source,
                                         line_no, value, previous));
        previous = ms;
        trace.opportunities_ms.push_back(ms);
    }
    if (trace.opportunities_ms.empty())
        return makeError(fmt::format("{}: no delivery opportunities in the trace", source));
    trace.period_ms = trace.opportunities_ms.back();
    if (trace.period_ms <= 0.0)
        return makeError(
            fmt::format("{}: the last stamp must be > 0 ms (the loop length)", source));
    return trace;
}

Expected<MahimahiTrace> loadMahimahiTrace(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return makeError(fmt::format("cannot open Mahimahi trace '{}'", path));
    std::ostringstream ss;
    ss << in.rdbuf();
    return parseMahimahiTrace(ss.str(), path);
}

TraceLink::TraceLink(std::string name, MahimahiTrace trace, double target_mean_bps,
                     double efficiency, RadioPower radio)
    : m_name(std::move(name)),
      m_trace(std::move(trace)),
      m_target_mean_bps(target_mean_bps),
      m_efficiency(efficiency),
      m_radio(radio) {
    QVR_CHECK(target_mean_bps > 0.0 && m_trace.period_ms > 0.0);
    // Dividing every stamp by target/trace mean scales the capacity to the target.
    m_time_scale = m_trace.meanBps() / target_mean_bps;
    for (double& t : m_trace.opportunities_ms)
        t *= m_time_scale;
    m_trace.period_ms *= m_time_scale;
}

LinkTransfer TraceLink::transfer(double start_ms, double payload_bytes) {
    if (payload_bytes <= 0.0)
        return {0.0, meanGoodputBps()};
    const auto& opp = m_trace.opportunities_ms;
    const double period = m_trace.period_ms;
    const int64_t packets =
        static_cast<int64_t>(std::ceil(payload_bytes / (m_efficiency * kMahimahiPacketBytes)));
    const double start = std::max(0.0, start_ms);
    double cycle = std::floor(start / period);
    const double offset = start - cycle * period;
    // Opportunities strictly after the start instant carry the payload.
    size_t idx =
        static_cast<size_t>(std::upper_bound(opp.begin(), opp.end(), offset) - opp.begin());
    const int64_t n = static_cast<int64_t>(opp.size());
    // Whole loops first, so a huge payload on a thin trace costs O(trace) not O(packets).
    int64_t remaining = packets;
    auto advance = [&]() {
        if (idx >= opp.size()) {
            idx = 0;
            cycle += 1.0;
        }
    };
    advance();
    if (remaining > n) {
        const int64_t loops = (remaining - 1) / n;
        cycle += static_cast<double>(loops);
        remaining -= loops * n;
    }
    size_t last = idx;
    for (int64_t k = 0; k < remaining; ++k) {
        advance();
        last = idx;
        ++idx;
    }
    const double finish_ms = cycle * period + opp[last];
    const double duration_ms = std::max(finish_ms - start, 1e-6);
    return {duration_ms, payload_bytes * 8.0 / (duration_ms * 1e-3)};
}

namespace {

// Huang et al., "A Close Examination of Performance and Power Characteristics of 4G LTE
// Networks", MobiSys 2012, Table 3 (downlink α, base β). 5G: assumption, see docs/MODEL.md.
constexpr RadioPower kWifiRadio{137.01, 132.86};
constexpr RadioPower kLteRadio{51.97, 1288.04};
constexpr RadioPower kNrRadio{15.0, 2500.0};
constexpr double kLteNominalBps = 100e6;

}  // namespace

const std::vector<std::string>& networkNames() {
    static const std::vector<std::string> names = {"wifi", "lte", "5g"};
    return names;
}

Expected<NetworkSpec> networkSpecByName(const std::string& name) {
    if (name == "wifi")
        return NetworkSpec{"wifi", 200e6, 20.0, kWifiRadio, ""};
    if (name == "lte" || name == "4g")
        return NetworkSpec{"lte", kLteNominalBps, 20.0, kLteRadio, ""};
    if (name == "5g")
        return NetworkSpec{"5g", 500e6, 20.0, kNrRadio, ""};
    if (name.rfind("trace:", 0) == 0) {
        std::string rest = name.substr(6);
        double mbps = kLteNominalBps / 1e6;
        const size_t at = rest.rfind('@');
        if (at != std::string::npos) {
            const std::string num = rest.substr(at + 1);
            char* end = nullptr;
            mbps = std::strtod(num.c_str(), &end);
            if (num.empty() || end != num.c_str() + num.size() || !std::isfinite(mbps) ||
                mbps <= 0.0 || mbps > 100'000.0)
                return makeError(fmt::format(
                    "network '{}': the rate after '@' must be a positive number of Mbps", name));
            rest = rest.substr(0, at);
        }
        if (rest.empty())
            return makeError(fmt::format("network '{}': expected trace:PATH[@MBPS]", name));
        return NetworkSpec{name, mbps * 1e6, std::numeric_limits<double>::infinity(), kLteRadio,
                           rest};
    }
    return makeError(fmt::format(
        "unknown network '{}': expected wifi, lte, 5g or trace:PATH[@MBPS] (a Mahimahi file)",
        name));
}

Expected<std::unique_ptr<Link>> makeLink(const NetworkSpec& spec, uint64_t seed) {
    const double efficiency = calibratedLinkEfficiency();
    if (spec.trace_path.empty()) {
        return std::unique_ptr<Link>(std::make_unique<NoisyLink>(
            spec.name, spec.nominal_bps, efficiency, spec.snr_db, spec.radio, seed));
    }
    auto trace = loadMahimahiTrace(spec.trace_path);
    if (!trace)
        return makeError(trace.error());
    return std::unique_ptr<Link>(std::make_unique<TraceLink>(
        spec.name, std::move(*trace), spec.nominal_bps, efficiency, spec.radio));
}

}  // namespace qvr
