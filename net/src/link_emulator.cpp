// Link emulator: bottleneck queue (rate or Mahimahi opportunities) + delay line + loss.
#include "qvr/net/link_emulator.h"

#include <algorithm>
#include <cmath>

#include "qvr/core/check.h"

namespace qvr::net {
namespace {

// Deliveries later than this (~146 years) are refused rather than rounded into overflow.
constexpr double kMaxDeliveryNs = 4.6e18;

}  // namespace

LinkEmulator::LinkEmulator(LinkSpec config)
    : m_config(std::move(config)),
      m_loss_rng(m_config.seed * 0x9E3779B97F4A7C15ull + 1),
      m_jitter_rng(m_config.seed * 0xBF58476D1CE4E5B9ull + 2),
      m_ge_rng(m_config.seed * 0x94D049BB133111EBull + 3),
      m_reorder_rng(m_config.seed * 0xD6E8FEB86659FD93ull + 4),
      m_dup_rng(m_config.seed * 0xA0761D6478BD642Full + 5) {
    QVR_CHECK(m_config.rate_bps >= 0 && m_config.delay_ms >= 0 && m_config.jitter_ms >= 0);
    QVR_CHECK_MSG(m_config.trace_path.empty() || m_config.trace,
                  "a trace link's spec must be loaded (loadLinkSpec)");
    QVR_CHECK(m_config.loss >= 0 && m_config.loss < 1 && m_config.queue_bytes > 0 &&
              m_config.max_in_flight_bytes > 0);
    QVR_CHECK(m_config.ge_p >= 0 && m_config.ge_p < 1 && m_config.ge_r >= 0 && m_config.ge_r <= 1 &&
              (m_config.ge_p == 0 || m_config.ge_r > 0) && m_config.ge_loss_bad > 0 &&
              m_config.ge_loss_bad <= 1);
    QVR_CHECK(m_config.reorder >= 0 && m_config.reorder < 1 && m_config.reorder_ms >= 0 &&
              m_config.reorder_ms <= 10'000 && m_config.duplicate >= 0 && m_config.duplicate < 1);
    QVR_CHECK(m_config.spike_every_ms >= 0 && m_config.spike_len_ms >= 0 &&
              m_config.spike_len_ms <= m_config.spike_every_ms && m_config.spike_extra_ms >= 0 &&
              m_config.spike_extra_ms <= 10'000);
    if (m_config.trace)
        m_delivery.emplace(m_config.trace, m_config.trace_target_bps);
}

double LinkEmulator::uniform01(std::mt19937_64& rng) {
    // 53 random bits: the same sequence on every standard library, unlike the distributions.
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double LinkEmulator::departureNs(double start_ns, int64_t bytes) {
    if (m_delivery) {
        // Mahimahi's rule (qvr/core/mahimahi.h) on the ns clock: the trace starts with the
        // link's first packet, so a session always sees the trace from its beginning.
        return m_delivery->departureMs(start_ns * 1e-6, bytes) * 1e6;
    }
    if (m_config.rate_bps > 0) {
        m_link_free_ns = std::max(start_ns, m_link_free_ns) +
                         static_cast<double>(bytes) * 8.0 * 1e9 / m_config.rate_bps;
        return m_link_free_ns;
    }
    return start_ns;
}

void LinkEmulator::drainQueue(int64_t now_ns) {
    while (!m_queue.empty() && m_queue.front().departure_ns <= static_cast<double>(now_ns)) {
        m_queue_bytes -= m_queue.front().bytes;
        m_queue.pop_front();
    }
}

int64_t LinkEmulator::queuedBytes(int64_t now_ns) {
    drainQueue(now_ns);
    return m_queue_bytes;
}

bool LinkEmulator::send(std::vector<uint8_t> packet, int64_t now_ns) {
    const int64_t bytes = static_cast<int64_t>(packet.size());
    ++m_stats.packets_in;
    m_stats.bytes_in += static_cast<uint64_t>(bytes);
    if (!m_started) {
        m_started = true;
        m_origin_ns = now_ns;
    }
    // The Gilbert-Elliott chain steps on every packet, before random loss looks at it, so the
    // bursts are the same whether or not loss= is on too.
    bool burst_lost = false;
    if (m_config.ge_p > 0) {
        const double u = uniform01(m_ge_rng);
        m_ge_bad = m_ge_bad ? !(u < m_config.ge_r) : u < m_config.ge_p;
        burst_lost =
            m_ge_bad && (m_config.ge_loss_bad >= 1.0 || uniform01(m_ge_rng) < m_config.ge_loss_bad);
    }
    if (m_config.loss > 0 && uniform01(m_loss_rng) < m_config.loss) {
        ++m_stats.dropped_loss;
        return false;
    }
    if (burst_lost) {
        ++m_stats.dropped_burst;
        return false;
    }
    drainQueue(now_ns);
    if (m_queue_bytes + bytes > m_config.queue_bytes ||
        m_flight_bytes + bytes > m_config.max_in_flight_bytes) {
        ++m_stats.dropped_queue;
        return false;
    }
    const double departure = departureNs(static_cast<double>(now_ns), bytes);
    // A configuration the parser would refuse (a rate near zero) could put a departure beyond
    // what int64 nanoseconds hold: such a packet can never leave, so it is a queue drop.
    if (!(departure + m_config.delay_ms * 1e6 + m_config.jitter_ms * 1e6 < kMaxDeliveryNs)) {
        ++m_stats.dropped_queue;
        return false;
    }
    if (departure > static_cast<double>(now_ns)) {
        m_queue.push_back({departure, bytes});
        m_queue_bytes += bytes;
    }
    double delay_ns = m_config.delay_ms * 1e6;
    if (m_config.jitter_ms > 0) {
        delay_ns += (2.0 * uniform01(m_jitter_rng) - 1.0) * m_config.jitter_ms * 1e6;
        delay_ns = std::max(0.0, delay_ns);
    }
    if (m_config.spike_every_ms > 0) {
        const double t_ms = static_cast<double>(now_ns - m_origin_ns) * 1e-6;
        if (std::fmod(t_ms, m_config.spike_every_ms) >=
            m_config.spike_every_ms - m_config.spike_len_ms) {
            delay_ns += m_config.spike_extra_ms * 1e6;
            ++m_stats.spiked;
        }
    }
    // Jitter never reorders: a packet leaves the delay line no earlier than the one before it.
    const int64_t deliver_ns =
        std::max(m_last_deliver_ns, static_cast<int64_t>(std::llround(departure + delay_ns)));
    const bool duplicate = m_config.duplicate > 0 && uniform01(m_dup_rng) < m_config.duplicate &&
                           m_flight_bytes + 2 * bytes <= m_config.max_in_flight_bytes;
    // A reordered packet leaves the delay line: the packets behind it keep their own times and
    // pass it.
    const bool reordered = m_config.reorder > 0 && uniform01(m_reorder_rng) < m_config.reorder;
    int64_t at_ns = deliver_ns;
    if (reordered) {
        ++m_stats.reordered;
        at_ns += static_cast<int64_t>(m_config.reorder_ms * 1e6);
    } else {
        m_last_deliver_ns = deliver_ns;
    }
    const auto put = [&](std::vector<uint8_t> p) {
        m_flight_bytes += bytes;
        if (reordered) {
            holdInOrder({std::move(p), at_ns});
        } else {
            m_flight.push_back({std::move(p), at_ns});
        }
    };
    if (duplicate) {
        ++m_stats.duplicated;
        put(packet);  // the copy, right ahead of the original at the same time
    }
    put(std::move(packet));
    return true;
}

void LinkEmulator::holdInOrder(InFlight p) {
    // Held packets' due times need not rise in send order (jitter, a spike ending): keep the
    // queue sorted so deliver() and nextDeliveryNs() can read its front.
    const auto at = std::upper_bound(m_held.begin(), m_held.end(), p.deliver_ns,
                                     [](int64_t t, const InFlight& h) { return t < h.deliver_ns; });
    m_held.insert(at, std::move(p));
}

void LinkEmulator::deliver(int64_t now_ns, std::vector<std::vector<uint8_t>>& out) {
    // The delay line and the held-back packets, merged by delivery time (the delay line first
    // on a tie: a held packet was due earlier than its time).
    while (true) {
        const bool flight = !m_flight.empty() && m_flight.front().deliver_ns <= now_ns;
        const bool held = !m_held.empty() && m_held.front().deliver_ns <= now_ns;
        if (!flight && !held) {
            break;
        }
        std::deque<InFlight>& from =
            flight && (!held || m_flight.front().deliver_ns <= m_held.front().deliver_ns) ? m_flight
                                                                                          : m_held;
        ++m_stats.packets_delivered;
        m_stats.bytes_delivered += from.front().bytes.size();
        m_flight_bytes -= static_cast<int64_t>(from.front().bytes.size());
        out.push_back(std::move(from.front().bytes));
        from.pop_front();
    }
}

std::optional<int64_t> LinkEmulator::nextDeliveryNs() const {
    if (m_flight.empty() && m_held.empty()) {
        return std::nullopt;
    }
    if (m_held.empty()) {
        return m_flight.front().deliver_ns;
    }
    if (m_flight.empty()) {
        return m_held.front().deliver_ns;
    }
    return std::min(m_flight.front().deliver_ns, m_held.front().deliver_ns);
}

}  // namespace qvr::net
