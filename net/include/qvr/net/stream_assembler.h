// Reassembles the headset's four media streams from datagrams: a stream's frame is complete
// when all its packets arrived; loss shows as a gap in the per-stream sequence numbers or a
// frame left incomplete past a reorder window or a timeout. After a loss the stream waits for
// a key frame (§3.2's streams are inter-coded video), which the client requests.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <vector>

#include "qvr/net/protocol.h"

namespace qvr::net {

struct AssemblerLimits {
    int max_partial_frames_per_stream = 8;
    int64_t max_buffered_bytes = 64 << 20;   // all partial frames of all streams
    uint32_t reorder_window_packets = 32;    // a frame is lost once seq passed its end by this
    int64_t frame_timeout_ns = 250'000'000;  // or once it saw no packet for this long
    // Selective retransmission: gaps are NACKed (again after nack_retry_ns, at most
    // max_nack_tries times) instead of being losses at once; a frame is then lost only when
    // it received nothing for retransmit_loss_timeout_ns (the reorder-window rule is off,
    // since retransmitted packets arrive far behind the newest). A frame still arriving is not
    // lost however long it takes: a whole-frame key frame of ~1 MB needs ~1.7 s at 4.6 Mbit/s.
    bool retransmit = false;
    int64_t nack_retry_ns = 30'000'000;
    int max_nack_tries = 2;
    int64_t retransmit_loss_timeout_ns = 100'000'000;
    // A partial frame that got nothing for this long has lost its tail (no later packet on the
    // stream reveals a gap): its missing packets are NACKed. "This long" follows the link's
    // pace like TCP's RTO: the smoothed gap between consecutive packets of a frame plus four
    // times its deviation, within [tail_nack_ns, tail_nack_max_ns]. A fixed 5 ms NACKed every
    // queued tail on a bursty link (the ATT trace has 37 delivery gaps > 5 ms a second), and
    // the answers, as large as the media, halved what the link had left for it.
    int64_t tail_nack_ns = 5'000'000;
    int64_t tail_nack_max_ns = 50'000'000;
    // A stalled frame has at most this many of its packets NACKed at a time: a 1 MB key frame
    // stalled by a delivery gap had its whole queued tail (hundreds of packets) sent again.
    int tail_nack_packets = 8;
    int max_missing_per_stream = 512;  // tracked gap packets; more are left to loss
};

struct CompletedStream {
    uint32_t frame_id = 0;
    uint8_t stream_id = 0;
    bool key_frame = false;
    bool decodable = false;  // a key frame, or no loss on this stream since the last key frame
    std::vector<uint8_t> bytes;
    uint16_t packets = 0;
    int64_t first_rx_ns = 0;
    int64_t last_rx_ns = 0;
};

struct LostStream {
    uint32_t frame_id = 0;
    uint8_t stream_id = 0;
    uint16_t packets_received = 0;
    uint16_t packet_count = 0;
    uint32_t bytes_received = 0;
    int64_t first_rx_ns = 0;
    int64_t last_rx_ns = 0;
};

struct AssemblerStats {
    uint64_t packets_accepted = 0;
    uint64_t packets_duplicate = 0;
    uint64_t packets_late = 0;          // for a frame already completed or declared lost
    uint64_t packets_inconsistent = 0;  // disagrees with earlier packets of its frame
    uint64_t packets_over_budget = 0;
    uint64_t seq_gap_packets = 0;  // packets presumed lost from sequence gaps
    uint64_t streams_completed = 0;
    uint64_t streams_lost = 0;
    uint64_t streams_undecodable = 0;  // completed while waiting for a key frame
    // Completed behind an earlier frame of the stream that may still come (a NACK in flight):
    // held so frames leave in stream order (an inter-coded decoder must see them so), and
    // completed after a later frame already left: dropped, it would break the decoder's chain.
    uint64_t streams_held = 0;
    uint64_t streams_stale = 0;
    uint64_t streams_released_early = 0;  // held too long (kMaxHeldPerStream): earlier skipped
    uint64_t nacks = 0;                   // NACK messages produced
    uint64_t packets_nacked = 0;          // sequence numbers asked for (tries counted)
    uint64_t packets_recovered = 0;       // gap packets that arrived after all
    // Forward error correction (fec.h): data packets rebuilt from parity, the stream frames
    // that completed only thanks to them, parity packets taken, and parity that came after
    // its frame was already complete (unneeded). Malformed parity never gets here: the
    // decoder drops and counts it.
    uint64_t fec_packets_recovered = 0;
    uint64_t fec_recoveries = 0;
    uint64_t fec_parity_received = 0;
    uint64_t fec_parity_unused = 0;
    uint64_t fec_failures = 0;  // a block with enough shards that did not decode (never seen)
};

class StreamAssembler {
public:
    explicit StreamAssembler(AssemblerLimits limits = {});

    // A packet that decodeMediaPacket accepted and whose session was checked.
    void onPacket(const MediaPacketView& packet, int64_t now_ns);
    // Declares frames that saw no packet for frame_timeout_ns lost.
    void expire(int64_t now_ns);

    std::vector<CompletedStream> takeCompleted();
    std::vector<LostStream> takeLost();
    // Streams on which a loss was newly detected since the last call (bit s = stream s).
    uint8_t takeLossMask();
    // Retransmission requests due (retransmit mode), grouped by 64 sequence numbers.
    std::vector<Nack> takeNacks();
    bool awaitingKeyFrame(uint8_t stream_id) const { return m_streams[stream_id].awaiting_key; }
    // Recent packet loss on all streams, from sequence gaps (parity included): an EWMA over
    // windows of kLossWindowPackets sequence numbers; what the client reports for FEC sizing.
    double lossRate() const { return m_loss_rate; }
    // How long a partial frame may go without a packet before its tail is NACKed (the link's
    // pace, AssemblerLimits::tail_nack_ns).
    int64_t tailNackNs() const;
    static constexpr uint32_t kLossWindowPackets = 256;
    const AssemblerStats& stats() const { return m_stats; }
    int64_t bufferedBytes() const { return m_buffered_bytes; }

private:
    struct Partial {
        bool key_frame = false;
        uint16_t packet_count = 0;
        uint32_t frame_bytes = 0;
        uint8_t fec_parity = 0;  // parity packets per block
        uint32_t first_seq = 0;
        uint32_t last_seq = 0;  // of the last parity packet when there is parity
        uint16_t received = 0;  // data and parity
        uint16_t data_have = 0;
        uint32_t bytes_received = 0;
        int64_t first_rx_ns = 0;
        int64_t last_rx_ns = 0;
        int64_t allocated = 0;
        bool fec_used = false;
        std::vector<uint8_t> bytes;   // data (whole shards when there is parity)
        std::vector<uint8_t> parity;  // parity shards
        std::vector<bool> have;
        std::vector<bool> have_parity;
    };
    struct Finished {
        uint32_t frame_id;
        uint32_t first_seq;
        uint32_t last_seq;
    };
    struct Held {
        uint32_t first_seq;
        CompletedStream stream;
    };
    struct Missing {
        uint32_t seq;
        int64_t last_nack_ns;
        int tries;
    };
    struct Stream {
        std::deque<Missing> missing;     // retransmit mode: gap packets not yet arrived
        std::vector<uint32_t> nack_now;  // sequence numbers to ask for in the next takeNacks
        bool has_seq = false;
        uint32_t next_seq = 0;
        bool awaiting_key = true;  // the first decodable frame is a key frame
        std::map<uint32_t, Partial> partials;
        std::deque<Finished> finished;  // recently completed or lost frames
        std::vector<Held> held;         // complete, waiting for an earlier frame (seq order)
        bool has_released = false;
        uint32_t released_first_seq = 0;  // the newest frame handed out
    };
    static constexpr size_t kMaxHeldPerStream = 16;

    void accept(const MediaPacketView& packet, int64_t now_ns);
    bool trackSequence(Stream& s, const MediaHeader& h, int64_t now_ns);
    void onGap(Stream& s, const MediaHeader& h, uint32_t d, int64_t now_ns);
    void sampleLossWindow();
    void sweepPartials(Stream& s, const MediaHeader& h, int64_t now_ns);
    std::map<uint32_t, Partial>::iterator partialFor(Stream& s, const MediaHeader& h,
                                                     int64_t now_ns);
    bool store(Partial& p, const MediaPacketView& packet);
    void finish(uint8_t stream_id, uint32_t frame_id, const Partial& p);
    void complete(uint8_t stream_id, std::map<uint32_t, Partial>::iterator it);
    void tryFec(Partial& p, int block);
    // Gap sequence numbers a frame with parity may still make good, or a finished frame's.
    bool coveredElsewhere(const Stream& s, uint32_t seq) const;
    // NACKs a frame's missing data packets, keeping at most max_outstanding of them asked for.
    void nackMissingData(Stream& s, const Partial& p, int64_t now_ns,
                         int max_outstanding = 1 << 30);
    // Hands out held frames that no earlier partial frame or NACKed packet precedes.
    void release(uint8_t stream_id);
    void declareLost(uint8_t stream_id, std::map<uint32_t, Partial>::iterator it);
    void samplePacketGap(int64_t gap_ns);
    bool isFinished(const Stream& s, uint32_t frame_id) const;

    AssemblerLimits m_limits;
    // The link's pace: smoothed gap between consecutive packets of a frame, and its deviation.
    bool m_gap_sampled = false;
    double m_gap_mean_ns = 0.0;
    double m_gap_dev_ns = 0.0;
    std::array<Stream, kMaxStreams> m_streams;
    int64_t m_buffered_bytes = 0;
    std::vector<CompletedStream> m_completed;
    std::vector<LostStream> m_lost;
    uint8_t m_loss_mask = 0;
    AssemblerStats m_stats;
    uint32_t m_window_expected = 0;
    uint32_t m_window_lost = 0;
    bool m_loss_sampled = false;
    double m_loss_rate = 0.0;
};

}  // namespace qvr::net
