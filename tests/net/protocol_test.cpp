// Wire protocol: every message round-trips; every malformed input is rejected with its reason
// (truncated, oversized, wrong version, bad magic, unknown type, bad field), never a crash.
#include "qvr/net/protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string_view>

#include "qvr/foveation/hmd_profile.h"
#include "qvr/net/fec.h"

namespace qvr::net {
namespace {

std::vector<uint8_t> bytesOf(size_t n, uint8_t seed) {
    std::vector<uint8_t> v(n);
    for (size_t i = 0; i < n; ++i) {
        v[i] = static_cast<uint8_t>(i * 31 + seed);
    }
    return v;
}

FrameRequest sampleRequest() {
    const LayerPlanner planner(defaultHmdProfile());
    const LayerPlan plan = planner.plan(Gaze{5.0, -3.0}, 12.0);
    Pose pose;
    pose.orientation = quatFromEulerDeg({20.0, -5.0, 1.0});
    pose.position_m = {0.1f, 1.6f, -0.3f};
    return makeFrameRequest(77, 123456789, pose, plan);
}

std::vector<ControlMessage> everyMessage() {
    ClientHello hello;
    hello.client_nonce.fill(7);
    hello.media_port = 40000;
    hello.settings = makeSessionSettings("x264", "small-320x360", 320, 360, 90.0);
    ServerChallenge ch;
    ch.server_nonce.fill(9);
    ch.session_id = 0x1122334455667788ull;
    ch.server_proof.fill(3);
    ClientAuth auth;
    auth.client_proof.fill(5);
    return {hello,
            ch,
            auth,
            Welcome{42, 50000},
            sampleRequest(),
            MediaAck{9, 3, true, 17, 20000, 100, 900, 20'000},
            KeyFrameRequest{0b0101, 12, KeyFrameReason::kPacketLoss},
            ThroughputReport{187'000'000, 30},
            Bye{ByeReason::kAuthFailed},
            Nack{2, 0xFFFFFFF0u, 0x8000000000000005ull},
            RouteConfirm{},
            KeepAlive{0x0102030405060708ull}};
}

TEST(NetProtocol, EveryControlMessageRoundTrips) {
    for (const ControlMessage& m : everyMessage()) {
        const std::vector<uint8_t> wire = encodeControl(m);
        ControlMessage back;
        ASSERT_EQ(decodeControl(wire, back), WireError::kNone) << m.index();
        ASSERT_EQ(back.index(), m.index());
        // The type byte on the wire is the message's own id (12, the sealed envelope, is none).
        EXPECT_EQ(wire[3], static_cast<uint8_t>(m.index() < 11 ? m.index() + 1 : m.index() + 2));
        // Re-encoding what was decoded gives the same bytes: nothing lost or invented.
        EXPECT_EQ(encodeControl(back), wire) << m.index();
    }
}

TEST(NetProtocol, ClientHelloCarriesTheSessionSettings) {
    ClientHello hello{{}, 40000, makeSessionSettings("raw", "run-480x540", 480, 540, 72.5)};
    ControlMessage back;
    ASSERT_EQ(decodeControl(encodeControl(hello), back), WireError::kNone);
    const auto& got = std::get<ClientHello>(back).settings;
    EXPECT_EQ(got, hello.settings);
    EXPECT_EQ(codecNameOf(got), "raw");
    EXPECT_EQ(profileTextOf(got), "run-480x540 480x540@72.5Hz");
    EXPECT_NE(got, makeSessionSettings("raw", "run-480x540", 480, 540, 90.0));
    // Names longer than the field are cut, never overflow; unprintable bytes are replaced.
    const auto longer = makeSessionSettings("a-very-long-codec-name", "p\x01q", 1, 1, 1.0);
    EXPECT_EQ(codecNameOf(longer), "a-very-long-code");
    EXPECT_EQ(profileTextOf(longer).substr(0, 3), "p?q");
    // A name must be printable ASCII then NUL padding: anything else is a bad field.
    const size_t codec_at = kControlHeaderBytes + kNonceBytes + 2;
    for (const auto& [offset, byte] : {std::pair<size_t, uint8_t>{1, 0x07},     // a control char
                                       std::pair<size_t, uint8_t>{5, 'x'},      // text after NUL
                                       std::pair<size_t, uint8_t>{0, 0xC3}}) {  // not ASCII
        auto wire = encodeControl(hello);
        wire[codec_at + offset] = byte;
        EXPECT_EQ(decodeControl(wire, back), WireError::kBadField) << offset;
    }
}

TEST(NetProtocol, SealedMediaOpensOnlyUnaltered) {
    MediaKey key{};
    key.fill(0x5A);
    uint32_t seq = 41;
    const auto frame = bytesOf(2 * kMediaChunkBytes + 10, 3);
    const auto plain = packetizeStream(7, seq, 3, 1, true, frame);
    for (const auto& p : plain) {
        auto d = p;
        sealMediaPacket(d, key);
        ASSERT_EQ(d.size(), p.size() + kMediaTagBytes);
        EXPECT_TRUE(std::equal(p.begin(), p.begin() + kMediaHeaderBytes, d.begin()));  // clear
        EXPECT_FALSE(std::equal(p.begin() + kMediaHeaderBytes, p.end(),
                                d.begin() + kMediaHeaderBytes));  // encrypted
        auto opened = d;
        ASSERT_EQ(openMediaPacket(opened, key), WireError::kNone);
        EXPECT_TRUE(std::equal(p.begin(), p.end(), opened.begin()));
        // Every single bit flipped anywhere past the version byte fails the tag.
        for (size_t byte = 3; byte < d.size(); byte += 37) {
            auto bad = d;
            bad[byte] ^= 0x10;
            EXPECT_EQ(openMediaPacket(bad, key), WireError::kBadMac) << byte;
        }
        MediaKey other = key;
        other[0] ^= 1;
        auto wrong = d;
        EXPECT_EQ(openMediaPacket(wrong, other), WireError::kBadMac);
    }
    std::vector<uint8_t> tiny(kMediaHeaderBytes + kMediaTagBytes - 1, 0);
    EXPECT_EQ(openMediaPacket(tiny, key), WireError::kTruncated);
    std::vector<uint8_t> big(kMaxSealedDatagramBytes + 1, 0);
    EXPECT_EQ(openMediaPacket(big, key), WireError::kOversized);
}

TEST(NetProtocol, ReplayWindowTakesEachSequenceNumberOnce) {
    ReplayWindow w;
    EXPECT_TRUE(w.accept(100));
    EXPECT_FALSE(w.accept(100));
    EXPECT_TRUE(w.accept(103));  // a gap
    EXPECT_TRUE(w.accept(101));  // filled late (a retransmission)
    EXPECT_FALSE(w.accept(101));
    EXPECT_TRUE(w.accept(102));
    EXPECT_TRUE(w.accept(100 + ReplayWindow::kBits));
    EXPECT_FALSE(w.accept(100));  // now older than the window
    EXPECT_FALSE(w.accept(103));  // same slot, older than the window
    EXPECT_TRUE(w.accept(101 + ReplayWindow::kBits));
    // Across the 32-bit wrap.
    ReplayWindow wrap;
    EXPECT_TRUE(wrap.accept(0xFFFFFFFEu));
    EXPECT_TRUE(wrap.accept(1));
    EXPECT_TRUE(wrap.accept(0xFFFFFFFFu));
    EXPECT_FALSE(wrap.accept(0xFFFFFFFEu));
    EXPECT_TRUE(wrap.accept(0));
}

TEST(NetProtocol, FrameRequestCarriesThePlan) {
    const LayerPlanner planner(defaultHmdProfile());
    const LayerPlan plan = planner.plan(Gaze{5.0, -3.0}, 12.0);
    ControlMessage back;
    ASSERT_EQ(decodeControl(encodeControl(sampleRequest()), back), WireError::kNone);
    const auto& r = std::get<FrameRequest>(back);
    EXPECT_EQ(r.frame_id, 77u);
    EXPECT_EQ(r.client_send_ns, 123456789u);
    const LayerPlan got = layerPlanOf(r);
    EXPECT_NEAR(got.e1_deg, plan.e1_deg, 1e-5);
    EXPECT_NEAR(got.e2_deg, plan.e2_deg, 1e-5);
    EXPECT_NEAR(got.s1, plan.s1, 1e-5);
    EXPECT_NEAR(got.s2, plan.s2, 1e-5);
    for (size_t e = 0; e < 2; ++e) {
        EXPECT_EQ(got.eyes[e].middle.rect, plan.eyes[e].middle.rect);
        EXPECT_EQ(got.eyes[e].outer.rect, plan.eyes[e].outer.rect);
        EXPECT_EQ(got.eyes[e].middle.width_px, plan.eyes[e].middle.width_px);
        EXPECT_EQ(got.eyes[e].outer.height_px, plan.eyes[e].outer.height_px);
    }
    EXPECT_EQ(got.middle_pixels, plan.middle_pixels);
    EXPECT_EQ(got.outer_pixels, plan.outer_pixels);
    EXPECT_NEAR(r.gaze.x_deg, 5.0, 1e-6);
}

TEST(NetProtocol, EveryTruncationIsRejected) {
    for (const ControlMessage& m : everyMessage()) {
        const std::vector<uint8_t> wire = encodeControl(m);
        for (size_t n = 0; n < wire.size(); ++n) {
            ControlMessage out;
            EXPECT_EQ(decodeControl(std::span(wire).first(n), out), WireError::kTruncated)
                << "type " << m.index() << " cut at " << n;
        }
    }
}

TEST(NetProtocol, HeaderErrorsAreNamed) {
    const std::vector<uint8_t> good = encodeControl(Bye{});
    ControlMessage out;
    auto wire = good;
    wire[0] = 'X';
    EXPECT_EQ(decodeControl(wire, out), WireError::kBadMagic);
    wire = good;
    wire[2] = kProtocolVersion + 1;
    EXPECT_EQ(decodeControl(wire, out), WireError::kWrongVersion);
    wire = good;
    wire[3] = 200;
    EXPECT_EQ(decodeControl(wire, out), WireError::kUnknownType);
    wire = good;
    wire[3] = 0;
    EXPECT_EQ(decodeControl(wire, out), WireError::kUnknownType);
    // A length field of 4 GB: rejected from the header alone, nothing read or allocated.
    wire = good;
    wire[4] = wire[5] = wire[6] = wire[7] = 0xFF;
    ControlHeader header;
    EXPECT_EQ(decodeControlHeader(wire, header), WireError::kOversized);
    wire = good;
    wire[4] = 2;  // Bye with a 2-byte payload: longer than its fixed layout
    wire.push_back(0);
    EXPECT_EQ(decodeControl(wire, out), WireError::kTrailingBytes);
    wire = good;
    wire.push_back(0);  // a byte after a complete message
    EXPECT_EQ(decodeControl(wire, out), WireError::kTrailingBytes);
}

TEST(NetProtocol, OutOfRangeFieldsAreRejected) {
    ControlMessage out;
    auto with = [](auto edit) {
        FrameRequest r = sampleRequest();
        edit(r);
        return encodeControl(r);
    };
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(decodeControl(with([&](FrameRequest& r) { r.pose.orientation.w = nan; }), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) { r.pose.orientation.w = 3.0f; }), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) { r.e1_deg = 200.0f; }), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) { r.e2_deg = r.e1_deg - 1.0f; }), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) { r.s1 = 0.5f; }), out), WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) { r.eyes[1].outer.rect.x1 = 1 << 20; }), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) { r.eyes[0].middle.width_px = -4; }), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(with([](FrameRequest& r) {
                                r.eyes[0].middle.rect.x0 = 10;
                                r.eyes[0].middle.rect.x1 = 5;
                            }),
                            out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(MediaAck{1, 4, true, 1, 1, 0, 0}), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(MediaAck{1, 0, true, 1, 1, 10, 5}), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(MediaAck{1, 0, true, 1, 1, 0, 0, 1'000'001}), out),
              WireError::kBadField);  // loss above 100 %
    EXPECT_EQ(decodeControl(encodeControl(KeyFrameRequest{0, 1, KeyFrameReason::kStart}), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(KeyFrameRequest{0x10, 1, KeyFrameReason::kStart}), out),
              WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(Welcome{0, 1}), out), WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(Nack{4, 1, 1}), out), WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(Nack{0, 1, 0}), out), WireError::kBadField);
    EXPECT_EQ(decodeControl(encodeControl(ClientHello{{}, 0}), out), WireError::kBadField);
    auto bye = encodeControl(Bye{});
    bye.back() = 99;
    EXPECT_EQ(decodeControl(bye, out), WireError::kBadField);
    bye.back() = kMaxByeReason + 1;
    EXPECT_EQ(decodeControl(bye, out), WireError::kBadField);
    bye.back() = kMaxByeReason;
    EXPECT_EQ(decodeControl(bye, out), WireError::kNone);
    // A key frame request's reason is one of the three the protocol names.
    auto key = encodeControl(KeyFrameRequest{1, 1, KeyFrameReason::kStart});
    EXPECT_EQ(decodeControl(key, out), WireError::kNone);
    for (const uint8_t reason : {0, 4}) {
        key.back() = reason;
        EXPECT_EQ(decodeControl(key, out), WireError::kBadField) << int{reason};
    }
}

TEST(NetProtocol, MediaPacketsRoundTripAndReassembleInOrder) {
    const auto frame = bytesOf(3 * kMediaChunkBytes + 17, 5);
    uint32_t seq = 1000;
    const auto packets = packetizeStream(99, seq, 7, 2, true, frame);
    ASSERT_EQ(packets.size(), 4u);
    EXPECT_EQ(seq, 1004u);
    std::vector<uint8_t> joined;
    for (size_t i = 0; i < packets.size(); ++i) {
        MediaPacketView v;
        ASSERT_EQ(decodeMediaPacket(packets[i], v), WireError::kNone);
        EXPECT_EQ(v.header.seq, 1000 + i);
        EXPECT_EQ(v.header.packet_index, i);
        EXPECT_EQ(v.header.packet_count, 4);
        EXPECT_EQ(v.header.frame_bytes, frame.size());
        EXPECT_EQ(v.header.frame_id, 7u);
        EXPECT_EQ(v.header.stream_id, 2);
        EXPECT_TRUE(v.header.key_frame);
        EXPECT_EQ(v.header.session_id, 99u);
        joined.insert(joined.end(), v.payload.begin(), v.payload.end());
    }
    EXPECT_EQ(joined, frame);
}

TEST(NetProtocol, MalformedMediaPacketsAreRejected) {
    uint32_t seq = 0;
    const auto frame = bytesOf(2 * kMediaChunkBytes + 5, 1);
    const auto packets = packetizeStream(5, seq, 1, 0, false, frame);
    const auto& first = packets[0];
    const auto& last = packets[2];
    MediaPacketView v;
    for (size_t n = 0; n < last.size(); ++n) {
        EXPECT_EQ(decodeMediaPacket(std::span(last).first(n), v), WireError::kTruncated) << n;
    }
    auto edit = [&](const std::vector<uint8_t>& base, size_t at, uint8_t value) {
        auto p = base;
        p[at] = value;
        return decodeMediaPacket(p, v);
    };
    EXPECT_EQ(edit(first, 0, 'Z'), WireError::kBadMagic);
    EXPECT_EQ(edit(first, 2, 9), WireError::kWrongVersion);
    EXPECT_EQ(edit(first, 3, 0x80), WireError::kBadField);                // unknown flag
    EXPECT_EQ(edit(first, 20, kMaxStreams), WireError::kBadField);        // stream id
    EXPECT_EQ(edit(first, 21, kFecMaxParity + 1), WireError::kBadField);  // FEC parity count
    EXPECT_EQ(edit(first, 3, 0x02), WireError::kBadField);    // parity flag, no parity count
    EXPECT_EQ(edit(first, 22, 3), WireError::kBadField);      // index ≥ count
    EXPECT_EQ(edit(first, 24, 2), WireError::kBadField);      // count disagrees with frame_bytes
    EXPECT_EQ(edit(first, 25, 0xFF), WireError::kOversized);  // count above the limit
    EXPECT_EQ(edit(first, 31, 0xFF), WireError::kOversized);  // frame_bytes ~4 GB
    EXPECT_EQ(edit(first, 27, 0xFF), WireError::kOversized);  // payload_bytes > chunk
    // payload_bytes says less than the datagram carries.
    EXPECT_EQ(edit(first, 26, 0), WireError::kTrailingBytes);
    auto big = first;
    big.resize(kMaxDatagramBytes + 1);
    EXPECT_EQ(decodeMediaPacket(big, v), WireError::kOversized);
    auto zero_session = first;
    std::fill(zero_session.begin() + 4, zero_session.begin() + 12, 0);
    EXPECT_EQ(decodeMediaPacket(zero_session, v), WireError::kBadField);
}

// Random corruption of valid messages: each decode either succeeds or names an error, and a
// message that decodes re-encodes to a decodable message. Run under ASan/UBSan in CI.
TEST(NetProtocol, EveryByeReasonAndWireErrorHasItsOwnText) {
    std::set<std::string_view> names, texts;
    for (uint8_t r = 0; r <= kMaxByeReason; ++r) {
        names.insert(byeReasonName(static_cast<ByeReason>(r)));
        texts.insert(byeReasonClientText(static_cast<ByeReason>(r)));
    }
    EXPECT_EQ(names.size(), kMaxByeReason + 1u);
    EXPECT_EQ(texts.size(), kMaxByeReason + 1u);
    EXPECT_EQ(names.count("?"), 0u);
    EXPECT_EQ(byeReasonName(ByeReason::kServerFull), "server full");
    EXPECT_EQ(byeReasonClientText(ByeReason::kServerFull), "is full");
    EXPECT_EQ(byeReasonName(static_cast<ByeReason>(kMaxByeReason + 1)), "?");
    EXPECT_EQ(byeReasonClientText(static_cast<ByeReason>(kMaxByeReason + 1)), "said bye");
    std::set<std::string_view> errors;
    for (int e = 0; e < kWireErrorCount; ++e)
        errors.insert(wireErrorName(static_cast<WireError>(e)));
    EXPECT_EQ(errors.size(), static_cast<size_t>(kWireErrorCount));
    EXPECT_EQ(errors.count("?"), 0u);
    EXPECT_EQ(wireErrorName(WireError::kBadMac), "bad MAC");
}

TEST(NetProtocol, RandomCorruptionNeverCrashes) {
    std::mt19937_64 rng(20210419);
    std::vector<std::vector<uint8_t>> seeds;
    for (const auto& m : everyMessage()) {
        seeds.push_back(encodeControl(m));
    }
    uint32_t seq = 0;
    for (auto& p : packetizeStream(3, seq, 1, 1, false, bytesOf(2500, 3))) {
        seeds.push_back(p);
    }
    DropCounters drops;
    int accepted = 0;
    for (int iter = 0; iter < 20000; ++iter) {
        auto bytes = seeds[rng() % seeds.size()];
        const int flips = 1 + static_cast<int>(rng() % 4);
        for (int f = 0; f < flips; ++f) {
            bytes[rng() % bytes.size()] = static_cast<uint8_t>(rng());
        }
        if (rng() % 4 == 0) {
            bytes.resize(rng() % (bytes.size() + 8));
        }
        ControlMessage m;
        const WireError ce = decodeControl(bytes, m);
        if (ce == WireError::kNone) {
            ++accepted;
            ControlMessage again;
            EXPECT_EQ(decodeControl(encodeControl(m), again), WireError::kNone);
        } else {
            drops.count(ce);
        }
        MediaPacketView v;
        const WireError me = decodeMediaPacket(bytes, v);
        if (me == WireError::kNone) {
            EXPECT_LE(v.payload.size(), kMediaChunkBytes);
            EXPECT_EQ(v.payload.size(), v.header.payload_bytes);
        }
    }
    EXPECT_GT(drops.total(), 10000u);
    EXPECT_GT(drops[WireError::kTruncated], 0u);
    EXPECT_GT(drops[WireError::kBadField], 0u);
    EXPECT_GT(accepted, 0);  // some flips land in free fields (nonces, ids)
}

}  // namespace
}  // namespace qvr::net
