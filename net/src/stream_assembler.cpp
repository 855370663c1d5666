// Media reassembly with bounded memory and loss detection (see the header).
#include "qvr/net/stream_assembler.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "qvr/core/check.h"
#include "qvr/net/fec.h"

namespace qvr::net {
namespace {

// Serial-number distance (RFC 1982 style): positive when a is after b.
int64_t seqAfter(uint32_t a, uint32_t b) {
    return static_cast<int32_t>(a - b);
}

constexpr size_t kFinishedMemory = 64;

}  // namespace

StreamAssembler::StreamAssembler(AssemblerLimits limits) : m_limits(limits) {
    QVR_CHECK(limits.max_partial_frames_per_stream > 0 && limits.max_buffered_bytes > 0);
}

bool StreamAssembler::isFinished(const Stream& s, uint32_t frame_id) const {
    return std::any_of(s.finished.begin(), s.finished.end(),
                       [&](const Finished& f) { return f.frame_id == frame_id; });
}

void StreamAssembler::finish(uint8_t stream_id, uint32_t frame_id, const Partial& p) {
    Stream& s = m_streams[stream_id];
    s.finished.push_back({frame_id, p.first_seq, p.last_seq});
    if (s.finished.size() > kFinishedMemory) {
        s.finished.pop_front();
    }
    // Nothing more to ask for in a frame completed or given up.
    std::erase_if(s.missing, [&](const Missing& m) {
        return seqAfter(m.seq, p.first_seq) >= 0 && seqAfter(m.seq, p.last_seq) <= 0;
    });
}

bool StreamAssembler::coveredElsewhere(const Stream& s, uint32_t seq) const {
    const auto in = [seq](uint32_t first, uint32_t last) {
        return seqAfter(seq, first) >= 0 && seqAfter(seq, last) <= 0;
    };
    for (const auto& [id, p] : s.partials) {
        if (p.fec_parity > 0 && in(p.first_seq, p.last_seq)) {
            return true;
        }
    }
    return std::any_of(s.finished.begin(), s.finished.end(),
                       [&](const Finished& f) { return in(f.first_seq, f.last_seq); });
}

void StreamAssembler::nackMissingData(Stream& s, const Partial& p, int64_t now_ns,
                                      int max_outstanding) {
    int outstanding = 0;  // this frame's packets asked for and not yet come
    for (const Missing& m : s.missing)
        if (seqAfter(m.seq, p.first_seq) >= 0 && seqAfter(m.seq, p.last_seq) <= 0)
            ++outstanding;
    for (uint32_t i = 0; i < p.packet_count && outstanding < max_outstanding; ++i) {
        const uint32_t want = p.first_seq + i;
        if (p.have[i] || static_cast<int>(s.missing.size()) >= m_limits.max_missing_per_stream ||
            std::any_of(s.missing.begin(), s.missing.end(),
                        [&](const Missing& m) { return m.seq == want; })) {
            continue;
        }
        s.missing.push_back({want, now_ns, 1});
        s.nack_now.push_back(want);
        ++outstanding;
    }
}

// Rebuilds a block's missing data packets once it holds as many shards as it has data packets.
void StreamAssembler::tryFec(Partial& p, int block) {
    const int k = fecBlockSize(p.packet_count, block);
    const int first = fecBlockFirst(block);
    const int m = p.fec_parity;
    std::vector<bool> have_data(static_cast<size_t>(k)), have_parity(static_cast<size_t>(m));
    int data = 0, parity = 0;
    for (int i = 0; i < k; ++i) {
        have_data[static_cast<size_t>(i)] = p.have[static_cast<size_t>(first + i)];
        data += have_data[static_cast<size_t>(i)] ? 1 : 0;
    }
    for (int j = 0; j < m; ++j) {
        have_parity[static_cast<size_t>(j)] = p.have_parity[static_cast<size_t>(block * m + j)];
        parity += have_parity[static_cast<size_t>(j)] ? 1 : 0;
    }
    if (data == k || data + parity < k) {
        return;
    }
    std::vector<uint8_t*> data_ptrs;
    for (int i = 0; i < k; ++i) {
        data_ptrs.push_back(p.bytes.data() + static_cast<size_t>(first + i) * kMediaChunkBytes);
    }
    std::vector<const uint8_t*> parity_ptrs;
    for (int j = 0; j < m; ++j) {
        parity_ptrs.push_back(p.parity.data() +
                              static_cast<size_t>(block * m + j) * kMediaChunkBytes);
    }
    if (!fecReconstruct(static_cast<int>(kMediaChunkBytes), data_ptrs, have_data, parity_ptrs,
                        have_parity)) {
        ++m_stats.fec_failures;
        return;
    }
    for (int i = 0; i < k; ++i) {
        if (!p.have[static_cast<size_t>(first + i)]) {
            p.have[static_cast<size_t>(first + i)] = true;
            ++p.data_have;
            ++m_stats.fec_packets_recovered;
        }
    }
    p.fec_used = true;
}

void StreamAssembler::declareLost(uint8_t stream_id, std::map<uint32_t, Partial>::iterator it) {
    Stream& s = m_streams[stream_id];
    const Partial& p = it->second;
    m_lost.push_back({it->first, stream_id, p.received, p.packet_count, p.bytes_received,
                      p.first_rx_ns, p.last_rx_ns});
    ++m_stats.streams_lost;
    m_buffered_bytes -= p.allocated;
    s.awaiting_key = true;
    m_loss_mask |= static_cast<uint8_t>(1u << stream_id);
    finish(stream_id, it->first, p);
    s.partials.erase(it);
    release(stream_id);
}

void StreamAssembler::samplePacketGap(int64_t gap_ns) {
    // RFC 6298's smoothing, on the gaps between consecutive packets of one frame.
    const double g = static_cast<double>(std::max<int64_t>(gap_ns, 0));
    if (!m_gap_sampled) {
        m_gap_sampled = true;
        m_gap_mean_ns = g;
        m_gap_dev_ns = g / 2.0;
        return;
    }
    m_gap_dev_ns = 0.75 * m_gap_dev_ns + 0.25 * std::fabs(m_gap_mean_ns - g);
    m_gap_mean_ns = 0.875 * m_gap_mean_ns + 0.125 * g;
}

int64_t StreamAssembler::tailNackNs() const {
    const double paced = m_gap_mean_ns + 4.0 * m_gap_dev_ns;
    const double cap = std::max<double>(static_cast<double>(m_limits.tail_nack_ns),
                                        static_cast<double>(m_limits.tail_nack_max_ns));
    return static_cast<int64_t>(std::clamp(paced, static_cast<double>(m_limits.tail_nack_ns), cap));
}

void StreamAssembler::onPacket(const MediaPacketView& packet, int64_t now_ns) {
    QVR_CHECK(packet.header.stream_id < kMaxStreams);
    accept(packet, now_ns);
    release(packet.header.stream_id);  // an answered NACK may unblock held frames
}

// Sequence gaps: packets that never came. A late packet (negative distance) fills no gap count
// back in; reordering on the emulated link cannot happen (it keeps order). Returns whether the
// packet is the one right after the stream's newest (a pacing sample).
bool StreamAssembler::trackSequence(Stream& s, const MediaHeader& h, int64_t now_ns) {
    if (!s.has_seq) {
        s.has_seq = true;
        s.next_seq = h.seq + 1;
        m_window_expected += 1;
        return false;
    }
    const int64_t d = seqAfter(h.seq, s.next_seq);
    if (d >= 0) {
        m_window_expected += static_cast<uint32_t>(d) + 1;
        m_window_lost += static_cast<uint32_t>(d);
        if (d > 0) {
            m_stats.seq_gap_packets += static_cast<uint64_t>(d);
        }
        onGap(s, h, static_cast<uint32_t>(d), now_ns);
        s.next_seq = h.seq + 1;
    }
    return d == 0;
}

// The d packets before h that never came: asked for again (retransmission) or given up on (a
// key frame is needed).
void StreamAssembler::onGap(Stream& s, const MediaHeader& h, uint32_t d, int64_t now_ns) {
    const uint32_t h_first = frameFirstSeq(h);
    for (uint32_t k = 0; k < d; ++k) {
        const uint32_t want = s.next_seq + k;
        // A frame with parity may still rebuild what it lost (it NACKs its data packets itself
        // once it cannot), and a finished frame needs nothing.
        if ((h.fec_parity > 0 && seqAfter(want, h_first) >= 0) || coveredElsewhere(s, want)) {
            continue;
        }
        if (!m_limits.retransmit) {
            s.awaiting_key = true;
            m_loss_mask |= static_cast<uint8_t>(1u << h.stream_id);
            break;
        }
        // Ask for the gap instead of giving up on it; a gap larger than what is tracked is left
        // to the loss timeout.
        if (static_cast<int>(s.missing.size()) >= m_limits.max_missing_per_stream) {
            break;
        }
        // A stalled tail may have been asked for already.
        if (std::none_of(s.missing.begin(), s.missing.end(),
                         [&](const Missing& m) { return m.seq == want; })) {
            s.missing.push_back({want, now_ns, 1});
            s.nack_now.push_back(want);
        }
    }
}

void StreamAssembler::sampleLossWindow() {
    if (m_window_expected < kLossWindowPackets) {
        return;
    }
    const double sample =
        static_cast<double>(m_window_lost) / static_cast<double>(m_window_expected);
    m_loss_rate = m_loss_sampled ? 0.75 * m_loss_rate + 0.25 * sample : sample;
    m_loss_sampled = true;
    m_window_expected = 0;
    m_window_lost = 0;
}

// Frames whose last packet is well behind the newest sequence number will not complete (without
// retransmission: with it, the late packets may still come). With retransmission, a frame with
// parity whose every packet was sent (the stream moved past its end) and that is still
// incomplete cannot rebuild itself: its missing data packets are NACKed.
void StreamAssembler::sweepPartials(Stream& s, const MediaHeader& h, int64_t now_ns) {
    for (auto it = s.partials.begin(); it != s.partials.end();) {
        const auto next = std::next(it);
        if (!m_limits.retransmit) {
            if (seqAfter(h.seq, it->second.last_seq) > m_limits.reorder_window_packets) {
                declareLost(h.stream_id, it);
            }
        } else if (it->second.fec_parity > 0 && seqAfter(h.seq, it->second.last_seq) > 0) {
            nackMissingData(s, it->second, now_ns);
        }
        it = next;
    }
}

// The partial frame h belongs to, made if it is new; end() when the budget has no room for it.
// Allocates only what the validated header allows, within the budget: makes room by giving up
// the oldest partial frames first. With parity the data is kept as whole shards for the code.
std::map<uint32_t, StreamAssembler::Partial>::iterator StreamAssembler::partialFor(
    Stream& s, const MediaHeader& h, int64_t now_ns) {
    auto it = s.partials.find(h.frame_id);
    if (it != s.partials.end()) {
        return it;
    }
    const uint32_t parity_count = parityPacketsFor(h.packet_count, h.fec_parity);
    const int64_t need = h.fec_parity == 0 ? static_cast<int64_t>(h.frame_bytes)
                                           : static_cast<int64_t>(h.packet_count + parity_count) *
                                                 static_cast<int64_t>(kMediaChunkBytes);
    while (!s.partials.empty() &&
           (static_cast<int>(s.partials.size()) >= m_limits.max_partial_frames_per_stream ||
            m_buffered_bytes + need > m_limits.max_buffered_bytes)) {
        declareLost(h.stream_id, s.partials.begin());
    }
    if (m_buffered_bytes + need > m_limits.max_buffered_bytes) {
        ++m_stats.packets_over_budget;
        return s.partials.end();
    }
    const uint32_t h_first = frameFirstSeq(h);
    Partial p;
    p.key_frame = h.key_frame;
    p.packet_count = h.packet_count;
    p.frame_bytes = h.frame_bytes;
    p.fec_parity = h.fec_parity;
    p.first_seq = h_first;
    p.last_seq = h_first + h.packet_count + parity_count - 1u;
    p.first_rx_ns = now_ns;
    if (h.fec_parity == 0) {
        p.bytes.resize(h.frame_bytes);
    } else {
        p.bytes.assign(static_cast<size_t>(h.packet_count) * kMediaChunkBytes, 0);
        p.parity.resize(static_cast<size_t>(parity_count) * kMediaChunkBytes);
        p.have_parity.assign(parity_count, false);
    }
    p.allocated = need;
    p.have.assign(h.packet_count, false);
    m_buffered_bytes += need;
    return s.partials.emplace(h.frame_id, std::move(p)).first;
}

// Copies the packet into its frame; false (and counted) when it does not fit the frame's first
// packet or repeats one.
bool StreamAssembler::store(Partial& p, const MediaPacketView& packet) {
    const MediaHeader& h = packet.header;
    if (p.packet_count != h.packet_count || p.frame_bytes != h.frame_bytes ||
        p.key_frame != h.key_frame || p.fec_parity != h.fec_parity ||
        p.first_seq != frameFirstSeq(h)) {
        ++m_stats.packets_inconsistent;
        return false;
    }
    if (h.parity ? p.have_parity[h.packet_index] : p.have[h.packet_index]) {
        ++m_stats.packets_duplicate;
        return false;
    }
    if (h.parity) {
        // decodeMediaPacket guaranteed a full shard and index < the frame's parity count.
        std::memcpy(p.parity.data() + static_cast<size_t>(h.packet_index) * kMediaChunkBytes,
                    packet.payload.data(), packet.payload.size());
        p.have_parity[h.packet_index] = true;
        ++m_stats.fec_parity_received;
    } else {
        // decodeMediaPacket guaranteed the payload fits: index·chunk + payload ≤ frame_bytes.
        std::memcpy(p.bytes.data() + static_cast<size_t>(h.packet_index) * kMediaChunkBytes,
                    packet.payload.data(), packet.payload.size());
        p.have[h.packet_index] = true;
        ++p.data_have;
        p.bytes_received += h.payload_bytes;
    }
    return true;
}

void StreamAssembler::accept(const MediaPacketView& packet, int64_t now_ns) {
    const MediaHeader& h = packet.header;
    Stream& s = m_streams[h.stream_id];
    const bool consecutive = trackSequence(s, h, now_ns);
    sampleLossWindow();
    if (m_limits.retransmit && !s.missing.empty()) {
        // An answer to a NACK: a gap packet (behind next_seq) or a lost tail (at or past it).
        const auto before = s.missing.size();
        std::erase_if(s.missing, [&](const Missing& m) { return m.seq == h.seq; });
        m_stats.packets_recovered += before - s.missing.size();
    }
    sweepPartials(s, h, now_ns);
    if (isFinished(s, h.frame_id)) {
        ++(h.parity ? m_stats.fec_parity_unused : m_stats.packets_late);
        return;
    }
    const auto it = partialFor(s, h, now_ns);
    if (it == s.partials.end()) {
        return;
    }
    Partial& p = it->second;
    if (!store(p, packet)) {
        return;
    }
    if (consecutive && p.received > 0) {
        samplePacketGap(now_ns - std::max(p.first_rx_ns, p.last_rx_ns));
    }
    ++p.received;
    p.last_rx_ns = now_ns;
    ++m_stats.packets_accepted;
    if (p.fec_parity > 0 && p.data_have < p.packet_count) {
        tryFec(p, h.parity ? h.packet_index / p.fec_parity : h.packet_index / kFecBlockData);
    }
    if (p.data_have == p.packet_count) {
        complete(h.stream_id, it);
    }
}

void StreamAssembler::complete(uint8_t stream_id, std::map<uint32_t, Partial>::iterator it) {
    Stream& s = m_streams[stream_id];
    Partial& p = it->second;
    CompletedStream done;
    done.frame_id = it->first;
    done.stream_id = stream_id;
    done.key_frame = p.key_frame;
    if (p.fec_used) {
        ++m_stats.fec_recoveries;
    }
    done.packets = p.packet_count;
    done.first_rx_ns = p.first_rx_ns;
    done.last_rx_ns = p.last_rx_ns;
    done.bytes = std::move(p.bytes);
    done.bytes.resize(p.frame_bytes);  // drops the code's padding
    m_buffered_bytes -= p.allocated;
    ++m_stats.streams_completed;
    const uint32_t first_seq = p.first_seq;
    finish(stream_id, it->first, p);
    s.partials.erase(it);
    if (s.has_released && seqAfter(first_seq, s.released_first_seq) < 0) {
        ++m_stats.streams_stale;  // a later frame already went to the decoder
        return;
    }
    auto pos = std::find_if(s.held.begin(), s.held.end(),
                            [&](const Held& h) { return seqAfter(h.first_seq, first_seq) > 0; });
    s.held.insert(pos, Held{first_seq, std::move(done)});
    release(stream_id);
}

void StreamAssembler::release(uint8_t stream_id) {
    Stream& s = m_streams[stream_id];
    while (!s.held.empty()) {
        const uint32_t first_seq = s.held.front().first_seq;
        // Only retransmission brings an earlier frame's packets after later ones (the link keeps
        // order); without it the earlier frame is lost and the held one leaves undecodable.
        const bool blocked =
            m_limits.retransmit &&
            (std::any_of(
                 s.partials.begin(), s.partials.end(),
                 [&](const auto& kv) { return seqAfter(first_seq, kv.second.first_seq) > 0; }) ||
             std::any_of(s.missing.begin(), s.missing.end(),
                         [&](const Missing& m) { return seqAfter(first_seq, m.seq) > 0; }));
        if (blocked) {
            if (s.held.size() <= kMaxHeldPerStream) {
                ++m_stats.streams_held;
                return;
            }
            // Memory stays bounded: skip what is still missing, as a loss.
            ++m_stats.streams_released_early;
            s.awaiting_key = true;
            m_loss_mask |= static_cast<uint8_t>(1u << stream_id);
        }
        CompletedStream done = std::move(s.held.front().stream);
        s.held.erase(s.held.begin());
        if (done.key_frame) {
            s.awaiting_key = false;
        }
        done.decodable = !s.awaiting_key;
        if (!done.decodable) {
            ++m_stats.streams_undecodable;
        }
        s.has_released = true;
        s.released_first_seq = first_seq;
        m_completed.push_back(std::move(done));
    }
}

void StreamAssembler::expire(int64_t now_ns) {
    for (uint8_t id = 0; id < kMaxStreams; ++id) {
        Stream& s = m_streams[id];
        auto& partials = s.partials;
        for (auto it = partials.begin(); it != partials.end();) {
            const auto next = std::next(it);
            const bool silent = now_ns - std::max(it->second.first_rx_ns, it->second.last_rx_ns) >
                                m_limits.frame_timeout_ns;
            // With retransmission, a frame is lost once nothing of it (data or an answered
            // NACK) came for retransmit_loss_timeout_ns. Not since its first packet: on a slow
            // link a frame larger than rate × timeout would never complete, and every key
            // frame asked for in its place would be lost the same way.
            const bool too_old = m_limits.retransmit &&
                                 now_ns - std::max(it->second.first_rx_ns, it->second.last_rx_ns) >
                                     m_limits.retransmit_loss_timeout_ns;
            if (silent || too_old) {
                declareLost(id, it);
            }
            it = next;
        }
        if (!m_limits.retransmit) {
            continue;
        }
        // A stalled partial frame: its tail was lost, and nothing after it shows the gap.
        for (const auto& [frame_id, p] : partials) {
            if (now_ns - std::max(p.first_rx_ns, p.last_rx_ns) >= tailNackNs()) {
                // A stall is not proof of loss: ask for the next few packets, not the whole
                // tail (most of a large frame's tail may still be in the bottleneck queue).
                nackMissingData(s, p, now_ns, m_limits.tail_nack_packets);
            }
        }
        // Ask again for what a retransmission did not bring; give up after the last try.
        for (Missing& m : s.missing) {
            if (now_ns - m.last_nack_ns >= m_limits.nack_retry_ns &&
                m.tries < m_limits.max_nack_tries) {
                ++m.tries;
                m.last_nack_ns = now_ns;
                s.nack_now.push_back(m.seq);
            }
        }
        const auto before = s.missing.size();
        std::erase_if(s.missing, [&](const Missing& m) {
            const bool give_up = m.tries >= m_limits.max_nack_tries &&
                                 now_ns - m.last_nack_ns >= m_limits.nack_retry_ns;
            // A packet of no frame we know of: a whole frame is gone, and no timeout will say
            // so (a partial frame is declared lost by its own timeout).
            if (give_up && !std::any_of(partials.begin(), partials.end(), [&](const auto& kv) {
                    return seqAfter(m.seq, kv.second.first_seq) >= 0 &&
                           seqAfter(m.seq, kv.second.last_seq) <= 0;
                })) {
                s.awaiting_key = true;
                m_loss_mask |= static_cast<uint8_t>(1u << id);
            }
            return give_up;
        });
        if (s.missing.size() != before) {
            release(id);
        }
    }
}

std::vector<Nack> StreamAssembler::takeNacks() {
    std::vector<Nack> out;
    for (uint8_t id = 0; id < kMaxStreams; ++id) {
        auto& seqs = m_streams[id].nack_now;
        if (seqs.empty()) {
            continue;
        }
        // Sorted in serial order relative to the first, then packed 64 to a message.
        const uint32_t base = seqs.front();
        std::sort(seqs.begin(), seqs.end(), [base](uint32_t a, uint32_t b) {
            return static_cast<uint32_t>(a - base) < static_cast<uint32_t>(b - base);
        });
        for (uint32_t seq : seqs) {
            if (out.empty() || out.back().stream_id != id ||
                static_cast<uint32_t>(seq - out.back().first_seq) >= 64) {
                out.push_back({id, seq, 0});
            }
            out.back().missing_mask |= uint64_t{1} << (seq - out.back().first_seq);
        }
        m_stats.packets_nacked += seqs.size();
        seqs.clear();
    }
    m_stats.nacks += out.size();
    return out;
}

std::vector<CompletedStream> StreamAssembler::takeCompleted() {
    return std::exchange(m_completed, {});
}

std::vector<LostStream> StreamAssembler::takeLost() {
    return std::exchange(m_lost, {});
}

uint8_t StreamAssembler::takeLossMask() {
    return std::exchange(m_loss_mask, 0);
}

}  // namespace qvr::net
