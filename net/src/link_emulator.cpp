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
    if (m_config.trace) {
        QVR_CHECK(m_config.trace->period_ms > 0 && !m_config.trace->stamps_ms.empty());
        // Dividing every stamp by target / mean compresses time so the mean becomes the target.
        const double mean = m_config.trace->meanBps();
        m_trace_ns_per_ms =
            m_config.trace_target_bps > 0 ? 1e6 * mean / m_config.trace_target_bps : 1e6;
        m_opp_left_bytes = kMahimahiPacketBytes;
    }
}

double LinkEmulator::uniform01(std::mt19937_64& rng) {
    // 53 random bits: the same sequence on every standard library, unlike the distributions.
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double LinkEmulator::opportunityNs(int64_t index) const {
    const auto& stamps = m_config.trace->stamps_ms;
    const int64_t n = static_cast<int64_t>(stamps.size());
    const int64_t loop = index / n;
    const double ms = static_cast<double>(stamps[static_cast<size_t>(index % n)]) +
                      static_cast<double>(loop) * static_cast<double>(m_config.trace->period_ms);
    return m_trace_origin_ns + ms * m_trace_ns_per_ms;
}

int64_t LinkEmulator::firstOpportunityAtOrAfter(double t_ns) const {
    const auto& stamps = m_config.trace->stamps_ms;
    const int64_t n = static_cast<int64_t>(stamps.size());
    const double period_ms = static_cast<double>(m_config.trace->period_ms);
    const double t_ms = std::max(0.0, (t_ns - m_trace_origin_ns) / m_trace_ns_per_ms);
    int64_t loop = static_cast<int64_t>(std::floor(t_ms / period_ms));
    int64_t index = loop * n;
    // Within the loop, the first stamp whose time is not before t; rounding can put t a hair
    // past the loop's last stamp, in which case the next loop's first stamp is it.
    const double within = t_ms - static_cast<double>(loop) * period_ms;
    const auto it = std::lower_bound(stamps.begin(), stamps.end(), within, [](int64_t s, double v) {
        return static_cast<double>(s) < v;
    });
    index += static_cast<int64_t>(it - stamps.begin());
    while (opportunityNs(index) < t_ns) {
        ++index;
    }
    return index;
}

double LinkEmulator::departureNs(double start_ns, int64_t bytes) {
    if (m_config.trace) {
        if (!m_trace_started) {
            // The trace starts with the link's first packet, not at the clock's epoch, so a
            // session always sees the trace from its beginning.
            m_trace_started = true;
            m_trace_origin_ns = start_ns;
        }
        if (opportunityNs(m_opp_index) < start_ns) {
            // Opportunities that passed with nothing queued are lost, as in Mahimahi.
            m_opp_index = firstOpportunityAtOrAfter(start_ns);
            m_opp_left_bytes = kMahimahiPacketBytes;
        }
        int64_t remaining = bytes;
        while (true) {
            const int64_t take = std::min(remaining, m_opp_left_bytes);
            remaining -= take;
            m_opp_left_bytes -= take;
            const double t = opportunityNs(m_opp_index);
            if (m_opp_left_bytes == 0) {
                ++m_opp_index;
                m_opp_left_bytes = kMahimahiPacketBytes;
            }
            if (remaining == 0) {
                return t;
            }
        }
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
