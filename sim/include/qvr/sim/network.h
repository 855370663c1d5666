// The headset's downlink (paper §5, Table 2): constant-rate profiles (Wi-Fi 200 Mbps, 4G LTE
// 100 Mbps, early 5G 500 Mbps) with 20 dB SNR white noise on the throughput, and trace-driven
// links replaying Mahimahi capacity traces. One calibration, from Table 1, turns nominal
// capacity into the goodput a frame sees. Models and sources: docs/MODEL.md.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/link_efficiency.h"
#include "qvr/core/mahimahi.h"

namespace qvr {

// Radio energy as Huang et al. (MobiSys 2012) model an active interface: P = α·R + β, so a
// transfer of b bits at goodput R costs b·(α + β/R).
struct RadioPower {
    double alpha_mw_per_mbps = 0.0;
    double beta_mw = 0.0;
    double energyPerBitNj(double goodput_bps) const;
};

struct LinkTransfer {
    double duration_ms = 0.0;
    double goodput_bps = 0.0;  // payload bits / duration, what acknowledgements measure
};

// A downlink the simulator sends frames over: a name, a nominal capacity, the payload share of it
// a transfer gets on average (efficiency) and a radio. A transfer is timed from its start, so
// trace-driven links see the capacity of that moment.
class Link {
public:
    virtual ~Link() = default;
    std::string_view name() const { return m_name; }
    double nominalBps() const { return m_nominal_bps; }
    double meanGoodputBps() const { return m_nominal_bps * m_efficiency; }
    double efficiency() const { return m_efficiency; }
    const RadioPower& radio() const { return m_radio; }
    // The packets a payload occupies: payload / (η·1500 bytes), rounded up, at least one.
    double packetsOf(double payload_bytes) const;
    virtual LinkTransfer transfer(double start_ms, double payload_bytes) = 0;
    // A new session on the link: a trace starts again with the next transfer.
    virtual void restart() {}

protected:
    Link(std::string name, double nominal_bps, double efficiency, RadioPower radio)
        : m_name(std::move(name)),
          m_nominal_bps(nominal_bps),
          m_efficiency(efficiency),
          m_radio(radio) {}

private:
    std::string m_name;
    double m_nominal_bps;
    double m_efficiency;
    RadioPower m_radio;
};

// Constant capacity C with white noise per sample, σ = 10^(−SNR/20) (noise amplitude relative to
// the signal for the given power ratio). A transfer of P packets (payload / (η·1500 bytes))
// sees the noise averaged over them: goodput η·C·(1 + σ/√P · n), n ~ N(0,1), floored at 5% of
// the mean so a deep fade stalls rather than reverses. snr_db = +inf turns it off.
class NoisyLink final : public Link {
public:
    NoisyLink(std::string name, double nominal_bps, double efficiency, double snr_db,
              RadioPower radio, uint64_t seed);
    LinkTransfer transfer(double start_ms, double payload_bytes) override;
    double noiseSigma() const { return m_sigma; }  // per sample
    // The relative spread of a transfer's goodput: σ/√packets.
    double noiseSigmaOver(double payload_bytes) const;

private:
    double m_sigma;
    std::mt19937_64 m_rng;
    std::normal_distribution<double> m_normal{0.0, 1.0};
};

// Replays a Mahimahi trace (qvr/core/mahimahi.h) rescaled to a target mean capacity, by
// Mahimahi's rule as the runtime's link emulator applies it (MahimahiDelivery): a payload of B
// bytes fills B / η bytes of opportunities, after what is still queued; the trace starts with
// the first transfer. Transfers in non-decreasing start order; restart() begins a new session.
class TraceLink final : public Link {
public:
    TraceLink(std::string name, std::shared_ptr<const MahimahiTrace> trace, double target_mean_bps,
              double efficiency, RadioPower radio);
    LinkTransfer transfer(double start_ms, double payload_bytes) override;
    void restart() override { m_delivery.restart(); }
    double timeScale() const { return m_delivery.msPerTraceMs(); }

private:
    MahimahiDelivery m_delivery;
};

// The paper simulator's links, named in the link grammar (qvr/core/link_spec.h): "wifi", "lte" or
// "4g", "5g", or "trace:PATH[@MBPS]" (a Mahimahi file rescaled to MBPS, by default the LTE
// profile's 100 Mbps; cellular radio power). It models no "none", "rate:MBPS" or ",key=value"
// options (they have no radio or noise here) and refuses them with a message.
struct NetworkSpec {
    std::string name;
    double nominal_bps = 0.0;
    double snr_db = 20.0;
    RadioPower radio;
    std::string trace_path;  // empty for constant-rate profiles
};
Expected<NetworkSpec> networkSpecByName(const std::string& name);
const std::vector<std::string>& networkNames();  // the built-in profiles
Expected<std::unique_ptr<Link>> makeLink(const NetworkSpec& spec, uint64_t seed);

}  // namespace qvr
