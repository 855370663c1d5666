// Throughput from acknowledgements (paper §4.1: LIWC "monitors the network's ACK packets" for
// Eq. 2's T_remote = DataSize / Throughput): per frame, the bytes acknowledged over the time from
// the frame's first send to its last ack, smoothed by an exponential moving average.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

namespace qvr::net {

class ThroughputEstimator {
public:
    // alpha: weight of a new sample. max_frames bounds the frames awaiting acks; older ones
    // (their acks lost with the connection) are forgotten.
    explicit ThroughputEstimator(double alpha = 0.25, size_t max_frames = 64);

    // One stream of a frame handed to the link.
    void onSend(uint32_t frame_id, int64_t bytes, int64_t now_ns);
    // The ack of one stream (complete or declared lost with bytes_acked received). When every
    // stream sent for the frame is acknowledged the frame yields a sample.
    void onAck(uint32_t frame_id, int64_t bytes_acked, int64_t now_ns);

    double throughputBps() const { return m_ema_bps; }  // 0 before the first sample
    uint32_t samples() const { return m_samples; }
    std::optional<double> lastSampleBps() const { return m_last_sample_bps; }

private:
    struct Pending {
        uint32_t frame_id;
        int64_t first_send_ns;
        int64_t bytes_acked;
        int streams_sent;
        int streams_acked;
    };
    double m_alpha;
    size_t m_max_frames;
    std::deque<Pending> m_pending;
    double m_ema_bps = 0.0;
    uint32_t m_samples = 0;
    std::optional<double> m_last_sample_bps;
};

}  // namespace qvr::net
