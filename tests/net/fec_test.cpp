// Forward error correction: ISA-L's Reed-Solomon code rebuilds any k of k + m shards exactly,
// the parity count follows the measured loss, the assembler completes frames from parity
// without a NACK and NACKs the data packets of a block that lost more than its parity, and
// malformed parity datagrams are refused by the decoder.
#include "qvr/net/fec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "qvr/net/protocol.h"
#include "qvr/net/stream_assembler.h"

namespace qvr::net {
namespace {

std::vector<uint8_t> randomBytes(size_t n, uint32_t seed) {
    std::vector<uint8_t> v(n);
    std::mt19937 rng(seed);
    for (auto& b : v) {
        b = static_cast<uint8_t>(rng());
    }
    return v;
}

// Encodes k shards of len bytes with m parity shards, erases `lost` (indices into k + m) and
// rebuilds; true when the data came back exactly.
bool roundTrip(int k, int m, int len, const std::vector<int>& lost, uint32_t seed) {
    std::vector<std::vector<uint8_t>> data, parity(static_cast<size_t>(m));
    std::vector<const uint8_t*> in;
    for (int i = 0; i < k; ++i) {
        data.push_back(randomBytes(static_cast<size_t>(len), seed + static_cast<uint32_t>(i)));
        in.push_back(data.back().data());
    }
    std::vector<uint8_t*> out;
    for (auto& p : parity) {
        p.resize(static_cast<size_t>(len));
        out.push_back(p.data());
    }
    fecEncode(len, in, out);
    std::vector<std::vector<uint8_t>> work = data;
    std::vector<bool> have_data(static_cast<size_t>(k), true),
        have_parity(static_cast<size_t>(m), true);
    for (int l : lost) {
        if (l < k) {
            have_data[static_cast<size_t>(l)] = false;
            std::fill(work[static_cast<size_t>(l)].begin(), work[static_cast<size_t>(l)].end(),
                      0xEE);
        } else {
            have_parity[static_cast<size_t>(l - k)] = false;
        }
    }
    std::vector<uint8_t*> wp;
    for (auto& w : work) {
        wp.push_back(w.data());
    }
    std::vector<const uint8_t*> pp;
    for (auto& p : parity) {
        pp.push_back(p.data());
    }
    if (!fecReconstruct(len, wp, have_data, pp, have_parity)) {
        return false;
    }
    return work == data;
}

TEST(NetFec, AnyKOfKPlusMShardsRebuildTheDataExactly) {
    std::mt19937 rng(7);
    for (auto [k, m] : {std::pair{1, 1}, {2, 1}, {4, 2}, {10, 3}, {40, 6}, {64, 16}, {64, 32}}) {
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<int> idx(static_cast<size_t>(k + m));
            std::iota(idx.begin(), idx.end(), 0);
            std::shuffle(idx.begin(), idx.end(), rng);
            const int erase = static_cast<int>(rng() % static_cast<uint32_t>(m + 1));  // 0..m
            idx.resize(static_cast<size_t>(erase));
            EXPECT_TRUE(roundTrip(k, m, 1200, idx, static_cast<uint32_t>(trial)))
                << "k=" << k << " m=" << m << " erased=" << erase;
        }
    }
    // Every data shard lost at once, m = k.
    std::vector<int> all(8);
    std::iota(all.begin(), all.end(), 0);
    EXPECT_TRUE(roundTrip(8, 8, 64, all, 3));
}

TEST(NetFec, MoreThanMLostIsNotRecovered) {
    EXPECT_FALSE(roundTrip(4, 2, 1200, {0, 1, 2}, 1));
    EXPECT_FALSE(roundTrip(10, 3, 1200, {0, 10, 11, 12}, 2));
}

TEST(NetFec, ParityFollowsTheMeasuredLossWithinFloorAndCap) {
    const FecPolicy policy;
    EXPECT_EQ(fecParityFor(4, 0.0, policy), 0);     // a clean link pays nothing
    EXPECT_EQ(fecParityFor(4, 0.0005, policy), 0);  // below min_loss
    EXPECT_EQ(fecParityFor(1, 0.02, policy), 1);    // floor (and P(1 of 1 lost) = 2% > 1%)
    const int m2 = fecParityFor(40, 0.02, policy);
    const int m5 = fecParityFor(40, 0.05, policy);
    EXPECT_GE(m2, 2);
    EXPECT_GT(m5, m2);
    EXPECT_LE(fecParityFor(64, 0.5, policy), policy.max_parity);  // cap
    EXPECT_LE(fecParityFor(2, 0.5, policy), 2);                   // at most max_overhead · k
    FecPolicy off = policy;
    off.enabled = false;
    EXPECT_EQ(fecParityFor(40, 0.05, off), 0);
}

std::vector<std::vector<uint8_t>> framePackets(uint32_t& seq, uint32_t frame, bool key,
                                               const std::vector<uint8_t>& bytes, uint8_t m) {
    return packetizeStream(1, seq, frame, 0, key, bytes, m);
}

void feed(StreamAssembler& a, const std::vector<uint8_t>& datagram, int64_t now_ns = 0) {
    MediaPacketView v;
    ASSERT_EQ(decodeMediaPacket(datagram, v), WireError::kNone);
    a.onPacket(v, now_ns);
}

TEST(NetFec, PacketizedParityDecodesAndNamesItsFrame) {
    uint32_t seq = 100;
    const auto bytes = randomBytes(70 * kMediaChunkBytes + 17, 4);  // 71 data: 2 blocks
    const auto packets = framePackets(seq, 9, true, bytes, 3);
    ASSERT_EQ(packets.size(), 71u + 2 * 3);
    EXPECT_EQ(seq, 100u + 77u);
    MediaPacketView v;
    ASSERT_EQ(decodeMediaPacket(packets.back(), v), WireError::kNone);
    EXPECT_TRUE(v.header.parity);
    EXPECT_EQ(v.header.fec_parity, 3);
    EXPECT_EQ(v.header.packet_index, 5);
    EXPECT_EQ(v.header.packet_count, 71);
    EXPECT_EQ(frameFirstSeq(v.header), 100u);
    ASSERT_EQ(decodeMediaPacket(packets[70], v), WireError::kNone);
    EXPECT_FALSE(v.header.parity);
    EXPECT_EQ(frameFirstSeq(v.header), 100u);
}

TEST(NetFec, AssemblerRebuildsLostPacketsWithoutANack) {
    AssemblerLimits limits;
    limits.retransmit = true;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    const auto f1 = randomBytes(10 * kMediaChunkBytes + 5, 1);
    auto p1 = framePackets(seq, 1, true, f1, 2);  // 11 data + 2 parity
    // Lose data packets 3 and 10 (the short last one): the two parity packets make them good.
    for (size_t i = 0; i < p1.size(); ++i) {
        if (i != 3 && i != 10) {
            feed(a, p1[i]);
        }
    }
    auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].bytes, f1);
    EXPECT_TRUE(done[0].decodable);
    EXPECT_EQ(a.stats().fec_recoveries, 1u);
    EXPECT_EQ(a.stats().fec_packets_recovered, 2u);
    EXPECT_EQ(a.stats().seq_gap_packets, 2u);
    EXPECT_TRUE(a.takeNacks().empty());  // no round trip
    a.expire(1'000'000'000);
    EXPECT_TRUE(a.takeNacks().empty());
    EXPECT_TRUE(a.takeLost().empty());
    EXPECT_EQ(a.bufferedBytes(), 0);
    // Parity that arrives for a finished frame is unneeded, not a new frame.
    feed(a, p1.back());
    EXPECT_EQ(a.stats().fec_parity_unused, 1u);
}

TEST(NetFec, LostParityOfACompleteFrameIsNoLoss) {
    StreamAssembler a;  // no retransmission: a real gap would mean waiting for a key frame
    uint32_t seq = 0;
    auto p1 = framePackets(seq, 1, true, randomBytes(3000, 1), 2);  // 3 data + 2 parity
    for (size_t i = 0; i < 3; ++i) {
        feed(a, p1[i]);
    }
    auto p2 = framePackets(seq, 2, false, randomBytes(3000, 2), 2);
    for (const auto& p : p2) {
        feed(a, p);
    }
    EXPECT_EQ(a.stats().seq_gap_packets, 2u);  // frame 1's parity never came
    EXPECT_FALSE(a.awaitingKeyFrame(0));
    const auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 2u);
    EXPECT_TRUE(done[1].decodable);
    EXPECT_EQ(a.takeLossMask(), 0);
}

TEST(NetFec, MoreLostThanParityFallsBackToNacksOfTheDataPackets) {
    AssemblerLimits limits;
    limits.retransmit = true;
    StreamAssembler a(limits);
    uint32_t seq = 0;
    const auto f1 = randomBytes(6 * kMediaChunkBytes, 1);
    auto p1 = framePackets(seq, 1, true, f1, 1);  // 6 data (seq 0..5) + 1 parity (seq 6)
    for (size_t i = 0; i < p1.size(); ++i) {
        if (i != 1 && i != 4) {
            feed(a, p1[i], 1000);
        }
    }
    EXPECT_TRUE(a.takeCompleted().empty());
    // The frame's parity arrived and the frame is still short: NACK its missing data packets
    // (here as soon as a later packet shows the frame ended: the next frame's first).
    auto p2 = framePackets(seq, 2, false, randomBytes(100, 2), 1);
    feed(a, p2[0], 2000);
    EXPECT_TRUE(a.takeCompleted().empty());  // frame 2 (one packet) waits for frame 1
    const auto nacks = a.takeNacks();
    ASSERT_EQ(nacks.size(), 1u);
    EXPECT_EQ(nacks[0].first_seq, 1u);
    EXPECT_EQ(nacks[0].missing_mask, (1u << 0) | (1u << 3));  // seq 1 and 4
    // One retransmission is enough: with the parity, 6 of 7 shards rebuild the rest.
    feed(a, p1[1], 3000);
    const auto done = a.takeCompleted();
    ASSERT_EQ(done.size(), 2u);  // in stream order
    EXPECT_EQ(done[0].bytes, f1);
    EXPECT_EQ(done[1].frame_id, 2u);
    EXPECT_EQ(a.stats().fec_recoveries, 1u);
    // Nothing of a completed frame is asked for again.
    a.expire(100'000'000);
    for (const Nack& n : a.takeNacks()) {
        EXPECT_NE(n.first_seq, 4u);
    }
}

TEST(NetFec, MoreLostThanParityWithoutRetransmissionIsALoss) {
    StreamAssembler a;
    uint32_t seq = 0;
    auto p1 = framePackets(seq, 1, true, randomBytes(6 * kMediaChunkBytes, 1), 1);
    for (size_t i = 0; i < p1.size(); ++i) {
        if (i != 1 && i != 4) {
            feed(a, p1[i]);
        }
    }
    EXPECT_EQ(a.takeLossMask(), 0);  // a gap in a frame with parity is not yet a loss
    a.expire(1'000'000'000);
    ASSERT_EQ(a.takeLost().size(), 1u);
    EXPECT_EQ(a.takeLossMask(), 1);
    EXPECT_TRUE(a.awaitingKeyFrame(0));
    EXPECT_EQ(a.stats().fec_recoveries, 0u);
}

TEST(NetFec, MalformedParityDatagramsAreRefused) {
    uint32_t seq = 0;
    const auto packets = framePackets(seq, 1, false, randomBytes(2500, 1), 2);  // 3 + 2
    ASSERT_EQ(packets.size(), 5u);
    const std::vector<uint8_t> good = packets[3];
    MediaPacketView v;
    ASSERT_EQ(decodeMediaPacket(good, v), WireError::kNone);
    auto bad = [&](auto mutate) {
        std::vector<uint8_t> d = good;
        mutate(d);
        return decodeMediaPacket(d, v);
    };
    // Parity index beyond the frame's parity count.
    EXPECT_EQ(bad([](auto& d) { d[22] = 2; }), WireError::kBadField);
    // Parity flag without a parity count.
    EXPECT_EQ(bad([](auto& d) { d[21] = 0; }), WireError::kBadField);
    // More parity per block than the protocol allows.
    EXPECT_EQ(bad([](auto& d) { d[21] = kFecMaxParity + 1; }), WireError::kBadField);
    // A short parity shard (payload size says so, datagram agrees).
    EXPECT_EQ(bad([](auto& d) {
                  d[26] = 100;
                  d[27] = 0;
                  d.resize(kMediaHeaderBytes + 100);
              }),
              WireError::kBadField);
    // Unknown flag bits.
    EXPECT_EQ(bad([](auto& d) { d[3] |= 0x04; }), WireError::kBadField);
    // A parity packet that disagrees with its frame's parity count reaches the assembler as
    // inconsistent and is dropped.
    StreamAssembler a;
    feed(a, packets[0]);
    std::vector<uint8_t> other = good;
    other[21] = 3;  // index 0 < 3 · 1 still valid alone
    other[22] = 0;
    ASSERT_EQ(decodeMediaPacket(other, v), WireError::kNone);
    a.onPacket(v, 0);
    EXPECT_EQ(a.stats().packets_inconsistent, 1u);
}

TEST(NetFec, LossRateFollowsSequenceGaps) {
    StreamAssembler a;
    uint32_t seq = 0;
    std::mt19937 rng(5);
    int sent = 0, dropped = 0;
    for (uint32_t f = 1; f <= 400; ++f) {
        for (const auto& p : framePackets(seq, f, true, randomBytes(2400, f), 0)) {
            ++sent;
            if (rng() % 20 == 0) {
                ++dropped;
                continue;
            }
            feed(a, p);
        }
    }
    EXPECT_NEAR(a.lossRate(), 0.05, 0.025);
    EXPECT_GT(dropped, 0);
    EXPECT_GT(sent, 700);
}

}  // namespace
}  // namespace qvr::net
