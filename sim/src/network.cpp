// Downlink models (paper §5, Table 2); sources in docs/MODEL.md.
#include "qvr/sim/network.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "qvr/core/link_spec.h"

namespace qvr {

double RadioPower::energyPerBitNj(double goodput_bps) const {
    if (goodput_bps <= 0.0)
        return 0.0;
    // mW per Mbps is nJ per bit; β mW over R bits/s is β·1e6/R nJ per bit.
    return alpha_mw_per_mbps + beta_mw * 1e6 / goodput_bps;
}

double Link::packetsOf(double payload_bytes) const {
    return std::max(1.0, std::ceil(payload_bytes / (m_efficiency * kMahimahiPacketBytes)));
}

NoisyLink::NoisyLink(std::string name, double nominal_bps, double efficiency, double snr_db,
                     RadioPower radio, uint64_t seed)
    : Link(std::move(name), nominal_bps, efficiency, radio),
      m_sigma(std::isfinite(snr_db) ? std::pow(10.0, -snr_db / 20.0) : 0.0),
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

double NoisyLink::noiseSigmaOver(double payload_bytes) const {
    return m_sigma / std::sqrt(packetsOf(payload_bytes));
}

TraceLink::TraceLink(std::string name, std::shared_ptr<const MahimahiTrace> trace,
                     double target_mean_bps, double efficiency, RadioPower radio)
    : Link(std::move(name), target_mean_bps, efficiency, radio),
      m_delivery(std::move(trace), target_mean_bps) {
    QVR_CHECK(target_mean_bps > 0.0);
}

LinkTransfer TraceLink::transfer(double start_ms, double payload_bytes) {
    if (payload_bytes <= 0.0)
        return {0.0, meanGoodputBps()};
    const double start = std::max(0.0, start_ms);
    const auto wire = static_cast<int64_t>(std::ceil(payload_bytes / efficiency()));
    const double finish_ms = m_delivery.departureMs(start, wire);
    // 0 when an opportunity at `start` carries it all: a caller that chains the next transfer at
    // start + duration must land on that instant, where the burst's other opportunities still
    // wait (a floor here once put it past them, so a frame's layers took a burst each).
    const double duration_ms = finish_ms - start;
    if (duration_ms <= 0.0)
        return {0.0, meanGoodputBps()};
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
    auto link = parseLinkSpec(name);
    if (!link)
        return makeError(link.error());
    const auto refuse = [&](const char* what) {
        return makeError(
            fmt::format("network '{}': the paper simulator models no {} (wifi, lte or 4g, 5g, "
                        "trace:PATH[@MBPS])",
                        name, what));
    };
    if (link->options > 0)
        return refuse("link options");
    if (link->profile == "wifi")
        return NetworkSpec{"wifi", link->rate_bps, 20.0, kWifiRadio, ""};
    if (link->profile == "lte")
        return NetworkSpec{"lte", link->rate_bps, 20.0, kLteRadio, ""};
    if (link->profile == "5g")
        return NetworkSpec{"5g", link->rate_bps, 20.0, kNrRadio, ""};
    if (link->profile == "trace") {
        const double bps = link->trace_target_bps > 0.0 ? link->trace_target_bps : kLteNominalBps;
        return NetworkSpec{name, bps, std::numeric_limits<double>::infinity(), kLteRadio,
                           link->trace_path};
    }
    return refuse(link->profile == "rate" ? "rate:MBPS link (it has no radio)"
                                          : "unshaped link ('none')");
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
        spec.name, std::make_shared<const MahimahiTrace>(std::move(*trace)), spec.nominal_bps,
        efficiency, spec.radio));
}

}  // namespace qvr
