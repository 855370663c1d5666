// Stream reassembly: complete frames in any packet order, loss detected from sequence gaps and
// timeouts, decodability after loss only from the next key frame, memory bounded.
#include "qvr/net/stream_assembler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "qvr/net/link_emulator.h"

namespace qvr::net {
namespace {

std::vector<uint8_t> frameBytes(size_t n, uint32_t seed) {
    std::vector<uint8_t> v(n);
    std::mt19937 rng(seed);
    for (auto& b : v) {
        b = static_cast<uint8_t>(rng());
    }
    return v;
}

void feed(StreamAssembler& a, const std::vector<uint8_t>& datagram, int64_t now_ns = 0) {
    MediaPacketView v;
    ASSERT_EQ(decodeMediaPacket(datagram, v), WireError::kNone);
    a.onPacket(v, now_ns);
}

TEST(NetStreamAssembler, CompletesFramesInAnyPacketOrder) {
    StreamAssembler a;
    uint32_t seq = 0;
    const auto bytes = frameBytes(10 * kMediaChunkBytes + 333, 1);
    auto packets = packetizeStream(1, seq, 5, 3, true, bytes);
    std::mt19937 rng(2);
    std::shuffle(packets.begin(), packets.end(), rng);
    for (const auto& p : packets) {
        feed(a, p);
    }
    feed(a, packets[0]);  // a duplicate after completion is late, not a second frame
    const auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].bytes, bytes);
    EXPECT_EQ(done[0].frame_id, 5u);
    EXPECT_EQ(done[0].stream_id, 3);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_EQ(a.stats().packets_late, 1u);
    EXPECT_EQ(a.bufferedBytes(), 0);
}

TEST(NetStreamAssembler, GapTriggersKeyFrameWaitUntilAKeyFrameCompletes) {
    StreamAssembler a;
    uint32_t seq = 0;
    for (const auto& p : packetizeStream(1, seq, 1, 0, true, frameBytes(3000, 1))) {
        feed(a, p);
    }
    EXPECT_FALSE(a.awaitingKeyFrame(0));
    // Frame 2 loses its middle packet.
    auto f2 = packetizeStream(1, seq, 2, 0, false, frameBytes(3000, 2));
    feed(a, f2[0]);
    feed(a, f2[2]);
    EXPECT_EQ(a.stats().seq_gap_packets, 1u);
    EXPECT_TRUE(a.awaitingKeyFrame(0));
    EXPECT_EQ(a.takeLossMask(), 0b0001);
    // Frame 3 (not a key frame) completes but cannot be decoded; frame 2 times out as lost.
    for (const auto& p : packetizeStream(1, seq, 3, 0, false, frameBytes(100, 3))) {
        feed(a, p, 1'000'000);
    }
    a.expire(1'000'000'000);
    const auto lost = a.takeLost();
    ASSERT_EQ(lost.size(), 1u);
    EXPECT_EQ(lost[0].frame_id, 2u);
    EXPECT_EQ(lost[0].packets_received, 2);
    auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 2u);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_FALSE(done[1].decodable);
    // A key frame restores decoding.
    for (const auto& p : packetizeStream(1, seq, 4, 0, true, frameBytes(100, 4))) {
        feed(a, p);
    }
    done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_FALSE(a.awaitingKeyFrame(0));
}

TEST(NetStreamAssembler, FrameIsLostOncePacketsPassItsEnd) {
    AssemblerLimits limits;
    limits.reorder_window_packets = 4;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    auto f1 = packetizeStream(1, seq, 1, 1, true, frameBytes(5 * kMediaChunkBytes, 1));
    for (size_t i = 0; i + 1 < f1.size(); ++i) {
        feed(a, f1[i]);  // the last packet never comes
    }
    const auto f2 = packetizeStream(1, seq, 2, 1, false, frameBytes(10 * kMediaChunkBytes, 2));
    for (size_t i = 0; i < 4; ++i) {
        feed(a, f2[i]);
        EXPECT_TRUE(a.takeLost().empty()) << i;  // still within the reorder window
    }
    feed(a, f2[4]);
    const auto lost = a.takeLost();
    ASSERT_EQ(lost.size(), 1u);
    EXPECT_EQ(lost[0].frame_id, 1u);
    EXPECT_EQ(lost[0].packets_received, 4);
    EXPECT_EQ(lost[0].packet_count, 5);
}

TEST(NetStreamAssembler, InconsistentPacketsAreDropped) {
    StreamAssembler a;
    uint32_t seq = 0;
    const auto f = packetizeStream(1, seq, 1, 0, true, frameBytes(3 * kMediaChunkBytes, 1));
    feed(a, f[0]);
    // The same frame id claiming another size.
    uint32_t seq2 = 1;
    const auto other = packetizeStream(1, seq2, 1, 0, true, frameBytes(5 * kMediaChunkBytes, 2));
    feed(a, other[1]);
    EXPECT_EQ(a.stats().packets_inconsistent, 1u);
    feed(a, f[0]);
    EXPECT_EQ(a.stats().packets_duplicate, 1u);
}

TEST(NetStreamAssembler, MemoryStaysWithinBudget) {
    AssemblerLimits limits;
    limits.max_buffered_bytes = 1 << 20;
    limits.max_partial_frames_per_stream = 3;
    StreamAssembler a(limits);
    // A peer that opens many big frames and never finishes them: each claims 4.9 MB.
    uint32_t seq = 0;
    for (uint32_t frame = 0; frame < 50; ++frame) {
        MediaHeader h;
        h.session_id = 1;
        h.seq = seq++;
        h.frame_id = frame;
        h.stream_id = static_cast<uint8_t>(frame % kMaxStreams);
        h.packet_count = kMaxPacketsPerFrame;
        h.frame_bytes = kMaxStreamFrameBytes;
        h.payload_bytes = kMediaChunkBytes;
        std::vector<uint8_t> payload(kMediaChunkBytes, 1), datagram;
        encodeMediaPacket(h, payload, datagram);
        feed(a, datagram);
        EXPECT_LE(a.bufferedBytes(), limits.max_buffered_bytes);
    }
    EXPECT_EQ(a.stats().packets_over_budget, 50u);
    // Small frames still fit, and at most three partials per stream are kept.
    for (uint32_t frame = 100; frame < 110; ++frame) {
        const auto f =
            packetizeStream(1, seq, frame, 0, false, frameBytes(2 * kMediaChunkBytes, frame));
        feed(a, f[0]);
    }
    EXPECT_LE(a.bufferedBytes(), 3 * 2 * static_cast<int64_t>(kMediaChunkBytes));
    EXPECT_GE(a.stats().streams_lost, 7u);
}

TEST(NetStreamAssembler, RetransmitModeNacksGapsAndRecovers) {
    AssemblerLimits limits;
    limits.retransmit = true;
    limits.nack_retry_ns = 10'000'000;
    limits.max_nack_tries = 2;
    limits.retransmit_loss_timeout_ns = 100'000'000;
    StreamAssembler a(limits);
    uint32_t seq = 500;
    const auto bytes = frameBytes(6 * kMediaChunkBytes, 7);
    const auto f = packetizeStream(1, seq, 1, 2, true, bytes);  // seqs 500..505
    feed(a, f[0], 0);
    feed(a, f[3], 1);  // 501, 502 missing
    auto nacks = a.takeNacks();
    ASSERT_EQ(nacks.size(), 1u);
    EXPECT_EQ(nacks[0].stream_id, 2);
    EXPECT_EQ(nacks[0].first_seq, 501u);
    EXPECT_EQ(nacks[0].missing_mask, 0b11u);
    EXPECT_FALSE(a.awaitingKeyFrame(2) && a.takeLossMask() != 0);  // not a loss yet
    feed(a, f[4], 2);
    feed(a, f[5], 3);
    feed(a, f[1], 4);  // the retransmission of 501
    // 502 is still missing after the retry interval: asked again, once.
    a.expire(20'000'000);
    nacks = a.takeNacks();
    ASSERT_EQ(nacks.size(), 1u);
    EXPECT_EQ(nacks[0].first_seq, 502u);
    EXPECT_EQ(nacks[0].missing_mask, 1u);
    a.expire(40'000'000);
    EXPECT_TRUE(a.takeNacks().empty());  // out of tries
    feed(a, f[2], 45'000'000);           // it made it after all
    const auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].bytes, bytes);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_EQ(a.stats().packets_recovered, 1u);  // 502 was already given up in the list
    EXPECT_EQ(a.stats().packets_nacked, 3u);
    EXPECT_TRUE(a.takeLost().empty());
}

// The client's path (replay window, then the assembler in retransmit mode) behind a link that
// reorders and duplicates (issue 12's faults), with no server to answer NACKs: the reordered
// packets come by themselves 5 ms late.
TEST(NetStreamAssembler, ReorderedAndDuplicatedPacketsCostNoFrameAndNoNackStorm) {
    AssemblerLimits limits;
    limits.retransmit = true;
    StreamAssembler a(limits);
    ReplayWindow replay;
    LinkEmulator link(parseLinkSpec("none,reorder=0.05:5,dup=0.05,seed=21").value());
    constexpr uint32_t kFrames = 300;
    constexpr int64_t kFrameNs = 14'000'000, kPacketNs = 50'000, kStepNs = 50'000;
    uint32_t seq = 0, replayed = 0, loss_masks = 0;
    std::vector<std::vector<uint8_t>> out;
    std::vector<std::vector<uint8_t>> frame;
    size_t next_packet = 0;
    for (int64_t now_ns = 0; now_ns < kFrames * kFrameNs + 100'000'000; now_ns += kStepNs) {
        const auto f = static_cast<uint32_t>(now_ns / kFrameNs);
        if (f < kFrames && now_ns % kFrameNs == 0) {
            frame = packetizeStream(1, seq, f, 0, f == 0,
                                    frameBytes(20 * kMediaChunkBytes, f));  // 20 packets
            next_packet = 0;
        }
        if (next_packet < frame.size() && now_ns % kFrameNs == int64_t(next_packet) * kPacketNs) {
            link.send(frame[next_packet++], now_ns);
        }
        out.clear();
        link.deliver(now_ns, out);
        for (const auto& p : out) {
            MediaPacketView v;
            ASSERT_EQ(decodeMediaPacket(p, v), WireError::kNone);
            if (!replay.accept(v.header.seq)) {
                ++replayed;
                continue;
            }
            a.onPacket(v, now_ns);
        }
        if (now_ns % 1'000'000 == 0) {
            a.expire(now_ns);
        }
        a.takeNacks();
        loss_masks += a.takeLossMask() != 0;
    }
    const auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), kFrames);
    for (const auto& d : done) {
        EXPECT_TRUE(d.decodable) << d.frame_id;
    }
    EXPECT_TRUE(a.takeLost().empty());
    EXPECT_EQ(loss_masks, 0u);  // no key-frame request
    const LinkStats ls = link.stats();
    ASSERT_GT(ls.reordered, 200u);
    ASSERT_GT(ls.duplicated, 200u);
    // Every copy stops at the replay window (the client counts it as a replayed datagram).
    EXPECT_EQ(replayed, ls.duplicated);
    EXPECT_EQ(a.stats().packets_duplicate, 0u);
    // At most one NACK per reordered packet, and each was needless: the packet came anyway.
    // (With a server each would draw one spurious retransmission, dropped as replayed.)
    EXPECT_LE(a.stats().packets_nacked, ls.reordered);
    EXPECT_EQ(a.stats().packets_recovered, a.stats().packets_nacked);
    // A known limit: the loss estimate (what FEC is sized from) counts a reordered packet as
    // lost when the gap shows, and does not take it back when it arrives.
    EXPECT_NEAR(a.lossRate(), 0.05, 0.02);  // 4.9 %
}

TEST(NetStreamAssembler, RetransmitModeDeclaresLossByTime) {
    AssemblerLimits limits;
    limits.retransmit = true;
    limits.retransmit_loss_timeout_ns = 100'000'000;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    const auto f1 = packetizeStream(1, seq, 1, 0, true, frameBytes(3 * kMediaChunkBytes, 1));
    feed(a, f1[0], 0);
    // Many later packets do not make frame 1 lost: its retransmission may still come.
    for (uint32_t frame = 2; frame < 20; ++frame) {
        for (const auto& p : packetizeStream(1, seq, frame, 0, false, frameBytes(5000, frame))) {
            feed(a, p, 1'000'000);
        }
    }
    EXPECT_TRUE(a.takeLost().empty());
    a.expire(150'000'000);
    const auto lost = a.takeLost();
    ASSERT_EQ(lost.size(), 1u);
    EXPECT_EQ(lost[0].frame_id, 1u);
    EXPECT_TRUE(a.awaitingKeyFrame(0));
}

// A frame larger than the link carries in the loss timeout is not lost while it keeps coming:
// a 40-packet key frame at one packet per 20 ms (0.8 s, ~2 Mbit/s) completes. Counted from its
// first packet, it was lost at 100 ms, and so was every key frame asked for in its place: no
// remote frame at all arrived on the ATT trace (docs/MODEL.md §13, the remote-on-ATT cell).
TEST(NetStreamAssembler, RetransmitModeKeepsAFrameThatIsStillArriving) {
    AssemblerLimits limits;
    limits.retransmit = true;
    limits.retransmit_loss_timeout_ns = 100'000'000;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    const auto bytes = frameBytes(40 * kMediaChunkBytes, 3);
    const auto f = packetizeStream(1, seq, 1, 0, true, bytes);
    ASSERT_EQ(f.size(), 40u);
    int64_t now = 0;
    for (const auto& p : f) {
        feed(a, p, now);
        now += 20'000'000;
        a.expire(now - 1);
        EXPECT_TRUE(a.takeLost().empty()) << now;
    }
    const auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].bytes, bytes);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_EQ(a.takeLossMask(), 0u);
    EXPECT_FALSE(a.awaitingKeyFrame(0));
}

// A bursty link (the Mahimahi traces: 2 ms and 12 ms delivery gaps in turn) must not make the
// client NACK every queued tail: the tail wait follows the packets' pace. A tail that really
// was lost is still asked for, within tail_nack_max_ns.
TEST(NetStreamAssembler, TailNacksFollowTheLinksPace) {
    AssemblerLimits limits;
    limits.retransmit = true;
    StreamAssembler a(limits);
    EXPECT_EQ(a.tailNackNs(), limits.tail_nack_ns);  // nothing seen yet: the floor
    uint32_t seq = 0;
    int64_t now = 0;
    uint64_t nacked_after_learning = 0;
    for (uint32_t frame = 1; frame <= 10; ++frame) {
        const auto f =
            packetizeStream(1, seq, frame, 0, frame == 1, frameBytes(20 * kMediaChunkBytes, frame));
        for (size_t i = 0; i < f.size(); ++i) {
            // Expire every millisecond up to the packet, as the client's timer does.
            const int64_t gap = i == 0 ? 30'000'000 : (i % 2 ? 2'000'000 : 12'000'000);
            for (int64_t t = now + 1'000'000; t < now + gap; t += 1'000'000)
                a.expire(t);
            now += gap;
            if (frame == 3)
                nacked_after_learning = a.stats().packets_nacked;
            feed(a, f[i], now);
        }
        a.takeNacks();
    }
    EXPECT_EQ(a.takeCompleted().size(), 10u);
    EXPECT_TRUE(a.takeLost().empty());
    // Learnt within the first frames; none after (a fixed 5 ms NACKed the tail at every 12 ms
    // gap: ~10 packets a frame).
    EXPECT_GT(a.tailNackNs(), 12'000'000);
    EXPECT_LE(a.tailNackNs(), limits.tail_nack_max_ns);
    EXPECT_EQ(a.stats().packets_nacked, nacked_after_learning);
    // A lost tail: 5 of 20 packets never come; it is NACKed once the paced wait has passed.
    const auto f = packetizeStream(1, seq, 11, 0, false, frameBytes(20 * kMediaChunkBytes, 11));
    for (size_t i = 0; i < 15; ++i) {
        now += i % 2 ? 2'000'000 : 12'000'000;
        feed(a, f[i], now);
    }
    a.expire(now + a.tailNackNs() - 1'000'000);
    EXPECT_TRUE(a.takeNacks().empty());
    a.expire(now + a.tailNackNs());
    const auto nacks = a.takeNacks();
    ASSERT_EQ(nacks.size(), 1u);
    EXPECT_EQ(nacks[0].first_seq, seq - 5u);  // packetizeStream left seq past the frame
    EXPECT_EQ(nacks[0].missing_mask, 0b11111u);
    // A long stalled tail is asked for a few packets at a time (tail_nack_packets), not whole:
    // most of it may still be queued in the bottleneck.
    const auto big = packetizeStream(1, seq, 12, 0, false, frameBytes(40 * kMediaChunkBytes, 12));
    for (size_t i = 0; i < 10; ++i) {
        now += i % 2 ? 2'000'000 : 12'000'000;
        feed(a, big[i], now);
    }
    a.expire(now + a.tailNackNs());
    // (Frame 11's tail, asked for again, may come in the same batch.)
    const auto batch = a.takeNacks();
    const auto it = std::find_if(batch.begin(), batch.end(),
                                 [&](const Nack& n) { return n.first_seq == seq - 30u; });
    ASSERT_NE(it, batch.end());
    EXPECT_EQ(it->missing_mask, 0xFFu);  // packets 10..17 of 40
}

// With retransmission an earlier frame can complete after a later one; an inter-coded decoder
// (and the codec's reference tracker: consecutive frame ids) must see them in order, so the
// later frame waits for the earlier one, or leaves undecodable once the earlier is lost.
TEST(NetStreamAssembler, RetransmitModeHandsOutFramesInStreamOrder) {
    AssemblerLimits limits;
    limits.retransmit = true;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    const auto b1 = frameBytes(3 * kMediaChunkBytes, 1);
    const auto f1 = packetizeStream(1, seq, 1, 0, true, b1);                    // seqs 0..2
    const auto f2 = packetizeStream(1, seq, 2, 0, false, frameBytes(2000, 2));  // 3..4
    const auto f3 = packetizeStream(1, seq, 3, 0, false, frameBytes(2000, 3));  // 5..6
    feed(a, f1[0], 0);
    feed(a, f1[2], 1);  // seq 1 missing: NACKed
    for (const auto& p : f2) {
        feed(a, p, 2);
    }
    EXPECT_EQ(a.takeNacks().size(), 1u);
    EXPECT_TRUE(a.takeCompleted().empty());  // frame 2 is complete but waits for frame 1
    EXPECT_GE(a.stats().streams_held, 1u);
    feed(a, f1[1], 3);  // the retransmission
    auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 2u);
    EXPECT_EQ(done[0].frame_id, 1u);
    EXPECT_EQ(done[1].frame_id, 2u);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_TRUE(done[1].decodable);
    EXPECT_EQ(done[0].bytes, b1);

    // Frame 4 loses a packet for good: frame 5 leaves once frame 4 is declared lost, and
    // cannot be decoded without it.
    const auto f4 = packetizeStream(1, seq, 4, 0, false, frameBytes(3 * kMediaChunkBytes, 4));
    const auto f5 = packetizeStream(1, seq, 5, 0, false, frameBytes(2000, 5));
    for (const auto& p : f3) {
        feed(a, p, 10);
    }
    feed(a, f4[0], 10);
    feed(a, f4[2], 10);
    for (const auto& p : f5) {
        feed(a, p, 11);
    }
    done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);  // frame 3
    EXPECT_EQ(done[0].frame_id, 3u);
    a.expire(200'000'000);  // past the loss timeout
    ASSERT_EQ(a.takeLost().size(), 1u);
    done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].frame_id, 5u);
    EXPECT_FALSE(done[0].decodable);
    EXPECT_TRUE(a.awaitingKeyFrame(0));
}

// A whole frame whose NACKs went unanswered is a loss too (no partial frame's timeout would
// say so), and an earlier frame completing after a later one left is dropped, not handed out.
TEST(NetStreamAssembler, RetransmitModeWholeFrameLossAndStaleFrames) {
    AssemblerLimits limits;
    limits.retransmit = true;
    limits.nack_retry_ns = 10'000'000;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    const auto f1 = packetizeStream(1, seq, 1, 0, true, frameBytes(2000, 1));   // 0..1
    const auto f2 = packetizeStream(1, seq, 2, 0, false, frameBytes(2000, 2));  // 2..3
    const auto f3 = packetizeStream(1, seq, 3, 0, false, frameBytes(2000, 3));  // 4..5
    for (const auto& p : f1) {
        feed(a, p, 0);
    }
    for (const auto& p : f3) {  // frame 2 entirely missing
        feed(a, p, 1);
    }
    EXPECT_EQ(a.takeCompleted().size(), 1u);  // frame 1; frame 3 waits for the NACKed 2..3
    a.expire(15'000'000);
    a.expire(30'000'000);  // out of tries: frame 2 is gone
    EXPECT_TRUE(a.awaitingKeyFrame(0));
    EXPECT_NE(a.takeLossMask(), 0);
    auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].frame_id, 3u);
    EXPECT_FALSE(done[0].decodable);
    // Frame 2's packets come after all: too late, frame 3 already left.
    feed(a, f2[0], 40'000'000);
    feed(a, f2[1], 40'000'000);
    EXPECT_TRUE(a.takeCompleted().empty());
    EXPECT_EQ(a.stats().streams_stale, 1u);
}

}  // namespace
}  // namespace qvr::net
