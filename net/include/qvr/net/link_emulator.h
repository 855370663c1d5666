// A userspace link between server and headset (paper §5's Wi-Fi / LTE / 5G profiles and
// Mahimahi traces), since the kernel's netem is unavailable: a drop-tail bottleneck queue served
// at a rate or by trace opportunities, then a delay line with jitter, with random loss before
// the queue. Pure in time: every call takes now_ns, so a fake clock makes it deterministic.
// Model and profiles: docs/NETWORK.md.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/net/mahimahi.h"

namespace qvr::net {

struct LinkConfig {
    std::string name = "none";
    double rate_bps = 0.0;                       // 0: no rate limit (and no trace)
    std::shared_ptr<const MahimahiTrace> trace;  // replaces rate_bps when set
    double trace_target_bps = 0.0;               // rescale the trace to this mean; 0: as recorded
    double delay_ms = 0.0;                       // one way, after the queue
    double jitter_ms = 0.0;                      // uniform in [-jitter, +jitter], order kept
    double loss = 0.0;                           // per-packet drop probability before the queue
    int64_t queue_bytes = 4 << 20;               // drop-tail bottleneck buffer
    int64_t max_in_flight_bytes = 64 << 20;      // the delay line (rate × delay) is bounded too
    uint64_t seed = 1;
    // Faults (issue 12's matrix), each off at 0; each draws from a seeded stream of its own, so
    // turning one on does not change which packets random loss, jitter or another fault pick.
    // Gilbert-Elliott burst loss: per packet Good→Bad with ge_p, Bad→Good with ge_r; a packet
    // sent in Bad is lost with ge_loss_bad (1: all). Long-run loss ge_loss_bad · ge_p /
    // (ge_p + ge_r), mean Bad run 1 / ge_r packets. The chain steps on every packet sent,
    // whether random loss took it or not: the two losses are independent.
    double ge_p = 0.0;
    double ge_r = 0.0;
    double ge_loss_bad = 1.0;
    // With probability `reorder` a packet is held reorder_ms longer, outside the order-keeping
    // delay line: packets sent after it overtake it.
    double reorder = 0.0;
    double reorder_ms = 5.0;
    double duplicate = 0.0;  // a packet is delivered twice (the copy right after it)
    // Delay spikes (a Wi-Fi stall): packets sent during the last spike_len_ms of every
    // spike_every_ms (from the link's first packet) wait spike_extra_ms more, order kept.
    double spike_every_ms = 0.0;
    double spike_len_ms = 0.0;
    double spike_extra_ms = 0.0;
    bool faulty() const {
        return ge_p > 0.0 || reorder > 0.0 || duplicate > 0.0 || spike_every_ms > 0.0;
    }
    bool shaped() const {
        return rate_bps > 0.0 || trace != nullptr || delay_ms > 0.0 || jitter_ms > 0.0 ||
               loss > 0.0 || faulty();
    }
};

// "none", "wifi" (200 Mbit/s), "lte" (100), "5g" (500) — paper Table 2 — "rate:MBPS", or
// "trace:PATH[@MBPS]" (a Mahimahi file, rescaled to MBPS when given), followed by options
// ",delay_ms=D", ",jitter_ms=J", ",loss=P" (0 ≤ P < 1), ",queue_kb=Q", ",seed=S", and the
// faults ",ge=P:R[:LOSS_BAD]" (Gilbert-Elliott), ",reorder=P[:MS]", ",dup=P",
// ",spike=EVERY:LEN:EXTRA" (ms).
// A trace starts (its time 0) with the first packet sent through the link.
Expected<LinkConfig> parseLinkSpec(const std::string& spec);
const std::vector<std::string>& linkProfileNames();

struct LinkStats {
    uint64_t packets_in = 0;
    uint64_t packets_delivered = 0;
    uint64_t dropped_loss = 0;   // random loss
    uint64_t dropped_queue = 0;  // the bottleneck buffer (or the delay line) was full
    uint64_t dropped_burst = 0;  // Gilbert-Elliott: sent in the Bad state (and not random loss)
    uint64_t reordered = 0;      // held back so later packets overtook it
    uint64_t duplicated = 0;     // delivered a second time
    uint64_t spiked = 0;         // sent during a delay spike
    uint64_t bytes_in = 0;
    uint64_t bytes_delivered = 0;
};

// The link seam the media sender writes through; LinkEmulator is the only implementation the
// runtime needs (an unshaped config passes packets through at once).
class PacketLink {
public:
    virtual ~PacketLink() = default;
    // Accepts a packet at now_ns; false when it was dropped (loss or full queue).
    virtual bool send(std::vector<uint8_t> packet, int64_t now_ns) = 0;
    // Appends the packets whose delivery time is ≤ now_ns, in order.
    virtual void deliver(int64_t now_ns, std::vector<std::vector<uint8_t>>& out) = 0;
    virtual std::optional<int64_t> nextDeliveryNs() const = 0;
    virtual int64_t queuedBytes(int64_t now_ns) = 0;  // waiting for the bottleneck
    virtual LinkStats stats() const = 0;
};

class LinkEmulator final : public PacketLink {
public:
    explicit LinkEmulator(LinkConfig config);
    bool send(std::vector<uint8_t> packet, int64_t now_ns) override;
    void deliver(int64_t now_ns, std::vector<std::vector<uint8_t>>& out) override;
    std::optional<int64_t> nextDeliveryNs() const override;
    int64_t queuedBytes(int64_t now_ns) override;
    LinkStats stats() const override { return m_stats; }
    const LinkConfig& config() const { return m_config; }
    // Trace mode: how much one trace millisecond lasts, in ns (1e6 · mean / target).
    double traceNsPerMs() const { return m_trace_ns_per_ms; }

private:
    // When the last byte of a packet of `bytes` entering the bottleneck at start_ns leaves it.
    double departureNs(double start_ns, int64_t bytes);
    double opportunityNs(int64_t index) const;
    int64_t firstOpportunityAtOrAfter(double t_ns) const;
    double uniform01(std::mt19937_64& rng);
    void drainQueue(int64_t now_ns);
    struct InFlight;
    void holdInOrder(InFlight p);

    struct InFlight {
        std::vector<uint8_t> bytes;
        int64_t deliver_ns;
    };
    struct Queued {
        double departure_ns;
        int64_t bytes;
    };
    LinkConfig m_config;
    std::mt19937_64 m_loss_rng;
    std::mt19937_64 m_jitter_rng;
    std::mt19937_64 m_ge_rng;
    std::mt19937_64 m_reorder_rng;
    std::mt19937_64 m_dup_rng;
    bool m_ge_bad = false;
    bool m_started = false;
    int64_t m_origin_ns = 0;       // the link's first packet: the spikes' time 0
    double m_link_free_ns = 0.0;   // rate mode: when the bottleneck finishes its backlog
    int64_t m_opp_index = 0;       // trace mode: the opportunity being filled
    int64_t m_opp_left_bytes = 0;  // bytes left in it
    double m_trace_ns_per_ms = 1e6;
    bool m_trace_started = false;
    double m_trace_origin_ns = 0.0;  // the time of the first packet: trace time 0
    int64_t m_last_deliver_ns = 0;
    std::deque<Queued> m_queue;  // departure times of packets still in the bottleneck
    int64_t m_queue_bytes = 0;
    std::deque<InFlight> m_flight;  // ordered by deliver_ns
    // Reordered packets, ordered by deliver_ns too: inserted in place, since jitter and spikes
    // make the times of successive held packets non-monotonic.
    std::deque<InFlight> m_held;
    int64_t m_flight_bytes = 0;
    LinkStats m_stats;
};

}  // namespace qvr::net
