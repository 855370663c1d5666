// Ack-based throughput EMA (see the header).
#include "qvr/net/throughput_estimator.h"

#include <algorithm>

#include "qvr/core/check.h"

namespace qvr::net {

ThroughputEstimator::ThroughputEstimator(double alpha, size_t max_frames)
    : m_alpha(alpha), m_max_frames(max_frames) {
    QVR_CHECK(alpha > 0 && alpha <= 1 && max_frames > 0);
}

void ThroughputEstimator::onSend(uint32_t frame_id, int64_t /*bytes*/, int64_t now_ns) {
    auto it = std::find_if(m_pending.begin(), m_pending.end(),
                           [&](const Pending& p) { return p.frame_id == frame_id; });
    if (it != m_pending.end()) {
        ++it->streams_sent;
        return;
    }
    if (m_pending.size() == m_max_frames) {
        m_pending.pop_front();
    }
    m_pending.push_back({frame_id, now_ns, 0, 1, 0});
}

void ThroughputEstimator::onAck(uint32_t frame_id, int64_t bytes_acked, int64_t now_ns) {
    auto it = std::find_if(m_pending.begin(), m_pending.end(),
                           [&](const Pending& p) { return p.frame_id == frame_id; });
    if (it == m_pending.end()) {
        return;  // a stale or unsolicited ack
    }
    it->bytes_acked += std::max<int64_t>(0, bytes_acked);
    if (++it->streams_acked < it->streams_sent) {
        return;
    }
    const int64_t elapsed_ns = now_ns - it->first_send_ns;
    if (elapsed_ns > 0 && it->bytes_acked > 0) {
        const double sample =
            static_cast<double>(it->bytes_acked) * 8.0 * 1e9 / static_cast<double>(elapsed_ns);
        m_ema_bps = m_samples == 0 ? sample : (1.0 - m_alpha) * m_ema_bps + m_alpha * sample;
        m_last_sample_bps = sample;
        ++m_samples;
    }
    m_pending.erase(it);
}

}  // namespace qvr::net
