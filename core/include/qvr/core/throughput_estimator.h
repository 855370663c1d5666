// Throughput from acknowledgements (paper §4.1: LIWC "monitors the network's ACK packets" for
// Eq. 2's T_remote = DataSize / Throughput): the bytes acknowledged over the time the link was
// busy with them, each an exponential moving average over frames (a ratio of averages, not an
// average of the frames' rates).
//
// A stream's busy time runs from its send, or from the previous ack if the link still carried
// earlier bytes then, to its ack. So neither the server's work between a frame's layers (their
// sends come one render + encode apart) nor the wait behind earlier frames reads as a slow
// link: on a 2 Mbit/s trace a frame's first send to its last ack read 0.3-1.5 Mbit/s while its
// streams' busy time read 0.6-3 (docs/LIWC.md).
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

namespace qvr {

class ThroughputEstimator {
public:
    // alpha: weight of a new sample. max_frames bounds the frames awaiting acks; older ones
    // (their acks lost with the connection) are forgotten. A frame sent after idle_ns without a
    // sample starts the average afresh: what the link did before the pause is no estimate of it
    // now (a headset that rendered everything itself for a while asks again).
    explicit ThroughputEstimator(double alpha = 0.25, size_t max_frames = 64,
                                 int64_t idle_ns = kIdleNs);

    // One stream of a frame handed to the link.
    void onSend(uint32_t frame_id, int64_t bytes, int64_t now_ns);
    // The ack of one stream (complete or declared lost with bytes_acked received). When every
    // stream sent for the frame is acknowledged the frame yields a sample.
    void onAck(uint32_t frame_id, int64_t bytes_acked, int64_t now_ns);

    // 0 before the first sample.
    double throughputBps() const { return m_samples > 0 ? m_ema_bits / m_ema_busy_s : 0.0; }
    uint32_t samples() const { return m_samples; }
    std::optional<double> lastSampleBps() const { return m_last_sample_bps; }

    static constexpr int64_t kIdleNs = 1'000'000'000;  // a second without a sample

private:
    static constexpr size_t kMaxStreamsPerFrame = 64;  // sends beyond it add no busy time
    struct Pending {
        uint32_t frame_id;
        std::deque<int64_t> unacked_send_ns;  // its streams' sends not yet acknowledged
        int64_t busy_ns;
        int64_t bytes_acked;
        int streams_sent;
        int streams_acked;
        bool restart;  // sent after an idle pause
    };
    double m_alpha;
    size_t m_max_frames;
    int64_t m_idle_ns;
    std::deque<Pending> m_pending;
    double m_ema_bits = 0.0;    // a frame's bits acknowledged
    double m_ema_busy_s = 0.0;  // a frame's busy time (> 0 once there is a sample)
    uint32_t m_samples = 0;
    std::optional<double> m_last_sample_bps;
    std::optional<int64_t> m_last_ack_ns;     // the newest ack: the link was busy until then
    std::optional<int64_t> m_last_sample_ns;  // when the newest sample was taken
};

}  // namespace qvr
