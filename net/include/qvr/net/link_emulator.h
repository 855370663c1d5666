// A userspace link between server and headset (paper §5's Wi-Fi / LTE / 5G profiles and
// Mahimahi traces), since the kernel's netem is unavailable: a drop-tail bottleneck queue served
// at a rate or by trace opportunities, then a delay line with jitter, with random loss before
// the queue. Pure in time: every call takes now_ns, so a fake clock makes it deterministic.
// Configured by a link spec (qvr/core/link_spec.h). Model and profiles: docs/NETWORK.md.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/link_spec.h"

namespace qvr::net {

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
    explicit LinkEmulator(LinkSpec config);  // config.trace loaded (loadLinkSpec) when a trace
    bool send(std::vector<uint8_t> packet, int64_t now_ns) override;
    void deliver(int64_t now_ns, std::vector<std::vector<uint8_t>>& out) override;
    std::optional<int64_t> nextDeliveryNs() const override;
    int64_t queuedBytes(int64_t now_ns) override;
    LinkStats stats() const override { return m_stats; }
    const LinkSpec& config() const { return m_config; }
    // Trace mode: how much one trace millisecond lasts, in ns (1e6 · mean / target).
    double traceNsPerMs() const { return m_delivery ? 1e6 * m_delivery->msPerTraceMs() : 1e6; }

private:
    // When the last byte of a packet of `bytes` entering the bottleneck at start_ns leaves it.
    double departureNs(double start_ns, int64_t bytes);
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
    LinkSpec m_config;
    std::mt19937_64 m_loss_rng;
    std::mt19937_64 m_jitter_rng;
    std::mt19937_64 m_ge_rng;
    std::mt19937_64 m_reorder_rng;
    std::mt19937_64 m_dup_rng;
    bool m_ge_bad = false;
    bool m_started = false;
    int64_t m_origin_ns = 0;      // the link's first packet: the spikes' time 0
    double m_link_free_ns = 0.0;  // rate mode: when the bottleneck finishes its backlog
    std::optional<MahimahiDelivery> m_delivery;  // trace mode: the opportunities
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
