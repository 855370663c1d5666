// The per-frame wire header of layer streams (paper §3.2) read as untrusted bytes (STYLE.md §6),
// the reference tracker's loss semantics, and the canvas policy for layers that change size.
#include "qvr/codec/frame_header.h"

#include <cstring>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/core/canvas_policy.h"

namespace qvr {
namespace {

using ::testing::HasSubstr;

std::vector<uint8_t> payloadOf(const std::string& s) {
    return {s.begin(), s.end()};
}

FrameHeader header(uint32_t id, bool key, uint16_t refresh = 0) {
    FrameHeader h;
    h.flags = key ? FrameHeader::kFlagKeyframe : 0;
    h.frame_id = id;
    h.width = 170;
    h.height = 190;
    h.refresh_frames = refresh;
    return h;
}

TEST(Crc32, MatchesTheStandardCheckValue) {
    EXPECT_EQ(crc32Ieee(payloadOf("123456789")), 0xCBF43926u);
    EXPECT_EQ(crc32Ieee({}), 0u);
}

TEST(FrameHeader, RoundTripsEveryField) {
    FrameHeader h = header(0xDEADBEEF, true, 45);
    h.width = 65535;
    h.height = 1;
    const auto payload = payloadOf("some payload bytes");
    const auto bytes = packFrame(h, payload);
    ASSERT_EQ(bytes.size(), FrameHeader::kSize + payload.size());
    auto parsed = parseFrame(bytes);
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    EXPECT_EQ(parsed->header.frame_id, 0xDEADBEEFu);
    EXPECT_TRUE(parsed->header.keyframe());
    EXPECT_EQ(parsed->header.refresh_frames, 45);
    EXPECT_EQ(parsed->header.width, 65535);
    EXPECT_EQ(parsed->header.height, 1);
    EXPECT_EQ(std::string(parsed->payload.begin(), parsed->payload.end()), "some payload bytes");
}

// The server stamps its time on the frame into a packed frame after encoding (outside the CRC,
// so the frame still parses); the headset reads it back without parsing. Too few bytes for a
// header say 0 and are left alone.
TEST(FrameHeader, TheServersTimeIsStampedAfterPackingAndReadBack) {
    FrameHeader h = header(7, false);
    h.server_us = 11;
    auto bytes = packFrame(h, payloadOf("layer"));
    EXPECT_EQ(frameServerUs(bytes), 11u);
    stampServerUs(bytes, 0xFEDCBA98u);
    EXPECT_EQ(frameServerUs(bytes), 0xFEDCBA98u);
    auto parsed = parseFrame(bytes);
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    EXPECT_EQ(parsed->header.server_us, 0xFEDCBA98u);
    EXPECT_EQ(parsed->header.frame_id, 7u);
    std::vector<uint8_t> short_frame(bytes.begin(), bytes.begin() + FrameHeader::kSize - 1);
    const std::vector<uint8_t> before = short_frame;
    stampServerUs(short_frame, 5);
    EXPECT_EQ(short_frame, before);
    EXPECT_EQ(frameServerUs(short_frame), 0u);
}

// The headset reads a decoded frame's flags (a new canvas) without parsing it again; too few
// bytes for a header say none. A flag no version knows is refused.
TEST(FrameHeader, FlagsAreReadFromTheHeaderAlone) {
    FrameHeader h = header(1, true);
    h.flags |= FrameHeader::kFlagNewCanvas;
    const auto opened = packFrame(h, payloadOf("idr"));
    auto parsed = parseFrame(opened);
    ASSERT_TRUE(parsed) << parsed.error();
    EXPECT_TRUE(parsed->header.newCanvas());
    EXPECT_EQ(frameFlags(opened), FrameHeader::kFlagKeyframe | FrameHeader::kFlagNewCanvas);
    EXPECT_EQ(frameFlags(packFrame(header(2, false), payloadOf("p"))), 0);
    EXPECT_EQ(frameFlags(std::span<const uint8_t>(opened).first(FrameHeader::kSize - 1)), 0);
    EXPECT_EQ(frameFlags({}), 0);
    auto unknown = opened;
    unknown[5] |= 8;
    EXPECT_FALSE(parseFrame(unknown));
}

TEST(FrameHeader, RejectsEachKindOfDamage) {
    const auto good = packFrame(header(3, false), payloadOf("0123456789abcdef"));
    auto expectError = [](std::vector<uint8_t> b, const std::string& what) {
        auto r = parseFrame(b);
        ASSERT_FALSE(r.ok());
        EXPECT_THAT(r.error(), HasSubstr(what));
    };
    expectError({}, "too short");
    expectError(std::vector<uint8_t>(good.begin(), good.begin() + 10), "too short");
    expectError(std::vector<uint8_t>(good.begin(), good.end() - 1), "truncated");
    auto longer = good;
    longer.push_back(0);
    expectError(longer, "trailing");
    auto magic = good;
    magic[0] ^= 0xFF;
    expectError(magic, "magic");
    auto version = good;
    version[4] = 9;
    expectError(version, "version");
    auto flags = good;
    flags[5] = 0x80;
    expectError(flags, "flags");
    auto zero = good;
    zero[12] = zero[13] = 0;
    expectError(zero, "zero width");
    for (size_t i = FrameHeader::kSize; i < good.size(); ++i) {
        auto flipped = good;
        flipped[i] ^= 0x10;
        expectError(flipped, "checksum");
    }
}

TEST(AnnexB, FindsIdrSlicesOnly) {
    const std::vector<uint8_t> idr = {0, 0, 0, 1, 0x67, 1, 2, 0, 0, 1, 0x65, 0x88};
    const std::vector<uint8_t> p = {0, 0, 0, 1, 0x41, 0x9a, 0, 0, 1, 0x06, 5};
    EXPECT_TRUE(annexBHasIdr(idr));
    EXPECT_FALSE(annexBHasIdr(p));
    EXPECT_FALSE(annexBHasIdr({}));
}

TEST(ReferenceTracker, RefusesUntilKeyframeAfterALoss) {
    ReferenceTracker t;
    EXPECT_FALSE(t.admit(header(0, false)).ok()) << "joined mid-stream";
    ASSERT_TRUE(t.admit(header(1, true)).ok());
    t.decoded(header(1, true), true);
    ASSERT_TRUE(t.admit(header(2, false)).ok());
    t.decoded(header(2, false), true);
    // Frame 3 lost.
    Status s = t.admit(header(4, false));
    ASSERT_FALSE(s.ok());
    EXPECT_THAT(s.error(), HasSubstr("lost"));
    EXPECT_TRUE(t.needsKeyframe());
    EXPECT_FALSE(t.admit(header(5, false)).ok());
    ASSERT_TRUE(t.admit(header(6, true)).ok());
    t.decoded(header(6, true), true);
    EXPECT_FALSE(t.needsKeyframe());
    EXPECT_TRUE(t.admit(header(7, false)).ok());
}

TEST(ReferenceTracker, DecodeFailureBreaksTheChain) {
    ReferenceTracker t;
    ASSERT_TRUE(t.admit(header(0, true)).ok());
    t.decoded(header(0, true), false);
    EXPECT_TRUE(t.needsKeyframe());
    EXPECT_FALSE(t.admit(header(1, false)).ok());
}

TEST(ReferenceTracker, IntraRefreshWithholdsPicturesForOnePeriod) {
    ReferenceTracker t;
    ASSERT_TRUE(t.admit(header(0, true, 4)).ok());
    t.decoded(header(0, true, 4), true);
    // Frame 1 lost: frames 2.. are decoded, pictures withheld for refresh + 1 frames (the wave
    // under way at the loss, and the frame its last column predicts from).
    int withheld = 0;
    for (uint32_t id = 2; id < 12; ++id) {
        ASSERT_TRUE(t.admit(header(id, false, 4)).ok());
        t.decoded(header(id, false, 4), true);
        withheld += t.withholdPicture() ? 1 : 0;
        EXPECT_FALSE(t.needsKeyframe());
    }
    EXPECT_EQ(withheld, 5);
}

TEST(CanvasPolicy, SmallSizeChangesKeepTheCanvas) {
    CanvasPolicy p(16, 0.10, 0.5, 30, 8192);
    const CanvasSize first = p.next(170, 190, true);
    EXPECT_TRUE(p.changed());
    EXPECT_EQ(first.width % 16, 0);
    EXPECT_EQ(first.height % 16, 0);
    EXPECT_GE(first.width, 187);
    EXPECT_GE(first.height, 209);
    for (int i = 0; i < 50; ++i) {
        p.next(160 + (i * 7) % 25, 180 + (i * 5) % 26, i % 10 == 0);
        EXPECT_FALSE(p.changed()) << i;
    }
}

// A canvas grows at once (the layer must fit: one IDR), and shrinks only after the layer stayed
// small for a while *and* on a frame the stream codes as a key frame anyway: a shrink on any frame
// was an IDR of its own, on all four streams at once 30 frames after a move up (6-7 KB, a
// 1.33 Mbit/s run's worst motion-to-photon).
TEST(CanvasPolicy, GrowsAtOnceShrinksOnlyAtAKeyFrameDue) {
    CanvasPolicy p(16, 0.10, 0.5, 5, 8192);
    p.next(100, 100, true);
    const CanvasSize grown = p.next(300, 120, false);
    EXPECT_TRUE(p.changed()) << "grows without a key frame due";
    EXPECT_GE(grown.width, 300);
    EXPECT_GE(grown.height, 120);
    for (int i = 0; i < 40; ++i) {
        p.next(60, 60, false);
        EXPECT_FALSE(p.changed()) << i;
    }
    const CanvasSize shrunk = p.next(60, 60, true);
    EXPECT_TRUE(p.changed());
    EXPECT_LT(shrunk.width, grown.width);
    EXPECT_GE(shrunk.width, 60);
    // Small for fewer than shrink_after frames: a key frame due does not shrink it.
    p.next(300, 120, false);
    p.next(60, 60, false);
    p.next(60, 60, true);
    EXPECT_FALSE(p.changed());
}

TEST(CanvasPolicy, NeverSmallerThanTheLayerEvenAtTheSizeLimit) {
    CanvasPolicy p(16, 0.5, 0.5, 5, 512);
    const CanvasSize c = p.next(500, 3, true);
    EXPECT_EQ(c.width, 512);
    EXPECT_GE(c.height, 3);
}

}  // namespace
}  // namespace qvr
