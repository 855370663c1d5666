// Layer-stream encode/decode (paper §3.2): x264 round trips within a PSNR bound, layers that
// change size every frame as e1 moves, loss and garbage reported as errors, and the raw fake
// behaving like the real codec.
#include "qvr/codec/video_codec.h"

#include <algorithm>
#include <cstdlib>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/codec/frame_header.h"
#include "qvr/codec/image_metrics.h"
#include "qvr/codec/synthetic_images.h"

namespace qvr {
namespace {

using ::testing::HasSubstr;

ImageRgba8 detailedImage(int w, int h, int phase = 0) {
    return syntheticDetailedImage(w, h, phase);
}
ImageRgba8 flatImage(int w, int h, uint8_t r = 90, uint8_t g = 120, uint8_t b = 160) {
    return syntheticFlatImage(w, h, r, g, b);
}
ImageRgba8 noiseImage(int w, int h, uint32_t seed) {
    return syntheticNoiseImage(w, h, seed);
}

// Bound for the detailed image at the default CRF 23: measured 33.8–35.5 dB, with 37.6 dB the
// ceiling that RGB→YUV 4:2:0 conversion alone allows (CRF 0); docs/CODEC.md.
constexpr double kMinPsnrDb = 32.0;

struct Pair {
    std::unique_ptr<VideoEncoder> encoder;
    std::unique_ptr<VideoDecoder> decoder;
};

Pair makePair(const CodecConfig& config = {}) {
    auto e = makeVideoEncoder(config);
    auto d = makeVideoDecoder(config);
    QVR_CHECK_MSG(e.ok() && d.ok(), "codec factory failed");
    return {std::move(e).value(), std::move(d).value()};
}

class CodecBackends : public ::testing::TestWithParam<std::string> {
protected:
    CodecConfig config() const {
        CodecConfig c;
        c.backend = GetParam();
        return c;
    }
};

TEST(Psnr, IsInfiniteForIdenticalAndFallsWithError) {
    const ImageRgba8 a = detailedImage(64, 48);
    ImageRgba8 b = a;
    EXPECT_TRUE(std::isinf(psnrRgb(a, b)));
    b.at(3, 3, 0) = static_cast<uint8_t>(b.at(3, 3, 0) ^ 0x40);
    const double one = psnrRgb(a, b);
    for (int x = 0; x < 64; ++x)
        b.at(x, 10, 1) = static_cast<uint8_t>(b.at(x, 10, 1) ^ 0x40);
    EXPECT_GT(one, psnrRgb(a, b));
    // MSE of a constant offset of 10 on every channel is 100: PSNR = 10 log10(255²/100).
    ImageRgba8 c = flatImage(8, 8, 100, 100, 100);
    ImageRgba8 d = flatImage(8, 8, 110, 110, 110);
    EXPECT_NEAR(psnrRgb(c, d), 28.1308, 1e-3);
}

TEST_P(CodecBackends, DetailedImageRoundTripsWithinPsnrBound) {
    Pair p = makePair(config());
    for (int phase = 0; phase < 6; ++phase) {
        const ImageRgba8 src = detailedImage(170, 190, phase * 3);
        auto enc = p.encoder->encode(src, false);
        ASSERT_TRUE(enc.ok()) << enc.error();
        EXPECT_EQ(enc->is_keyframe, phase == 0) << phase;
        EXPECT_EQ(enc->frame_id, static_cast<uint32_t>(phase));
        auto dec = p.decoder->decode(enc->bytes);
        ASSERT_TRUE(dec.ok()) << dec.error();
        ASSERT_EQ(dec->width(), 170);
        ASSERT_EQ(dec->height(), 190);
        const double psnr = psnrRgb(src, *dec);
        EXPECT_GT(psnr, kMinPsnrDb) << "frame " << phase;
        if (GetParam() == "raw") {
            EXPECT_TRUE(std::isinf(psnr));
        }
    }
}

TEST_P(CodecBackends, SizeChangesEveryFrameWithoutAKeyframeEveryFrame) {
    Pair p = makePair(config());
    int keyframes = 0;
    const int frames = 24;
    for (int i = 0; i < frames; ++i) {
        // A periphery layer as e1 wobbles: a few pixels each way, every frame a new size.
        const int w = 170 + ((i * 7) % 13) - 6;
        const int h = 190 + ((i * 5) % 11) - 5;
        const ImageRgba8 src = detailedImage(w, h, i * 2);
        auto enc = p.encoder->encode(src, false);
        ASSERT_TRUE(enc.ok()) << enc.error();
        keyframes += enc->is_keyframe ? 1 : 0;
        auto dec = p.decoder->decode(enc->bytes);
        ASSERT_TRUE(dec.ok()) << "frame " << i << ": " << dec.error();
        ASSERT_EQ(dec->width(), w);
        ASSERT_EQ(dec->height(), h);
        EXPECT_GT(psnrRgb(src, *dec), kMinPsnrDb) << "frame " << i;
    }
    if (GetParam() == "x264") {
        EXPECT_EQ(keyframes, 1);
        EXPECT_EQ(p.encoder->stats().reopens, 0);
        EXPECT_GE(p.encoder->canvasWidth(), 176);
    } else {
        EXPECT_EQ(keyframes, frames) << "the raw fake restarts on every size change";
    }
}

TEST(X264Codec, OutgrowingTheCanvasReopensWithAKeyframeAndDecodes) {
    Pair p = makePair();
    const int sizes[][2] = {{170, 190}, {172, 191}, {270, 300}, {268, 301}, {170, 190}};
    const bool expect_key[] = {true, false, true, false, false};
    for (int i = 0; i < 5; ++i) {
        const ImageRgba8 src = detailedImage(sizes[i][0], sizes[i][1], i);
        auto enc = p.encoder->encode(src, false);
        ASSERT_TRUE(enc.ok()) << enc.error();
        EXPECT_EQ(enc->is_keyframe, expect_key[i]) << i;
        // The header says which key frames opened a canvas (LIWC reads them as a move's cost).
        EXPECT_EQ((frameFlags(enc->bytes) & FrameHeader::kFlagNewCanvas) != 0, expect_key[i]) << i;
        auto dec = p.decoder->decode(enc->bytes);
        ASSERT_TRUE(dec.ok()) << dec.error();
        EXPECT_EQ(dec->width(), sizes[i][0]);
        EXPECT_GT(psnrRgb(src, *dec), kMinPsnrDb);
    }
    EXPECT_EQ(p.encoder->stats().reopens, 1);
}

// A layer that stays far smaller than its canvas keeps the canvas until the stream's periodic key
// frame, and shrinks there: no IDR of its own (a shrink on any frame was one on every stream at
// once, the worst motion-to-photon of a 1.33 Mbit/s run).
TEST(X264Codec, ACanvasShrinksOnlyAtTheStreamsPeriodicKeyFrame) {
    CodecConfig c;
    c.keyint_frames = 50;
    Pair p = makePair(c);
    auto first = p.encoder->encode(detailedImage(480, 440, 0), false);
    ASSERT_TRUE(first.ok() && p.decoder->decode(first->bytes).ok());
    for (int i = 1; i < 60; ++i) {
        auto enc = p.encoder->encode(detailedImage(200, 180, i), false);
        ASSERT_TRUE(enc.ok()) << enc.error();
        const bool opened = (frameFlags(enc->bytes) & FrameHeader::kFlagNewCanvas) != 0;
        EXPECT_EQ(enc->is_keyframe, i == 50) << i;
        EXPECT_EQ(opened, i == 50) << i << ": the shrink waits for the periodic key frame";
        ASSERT_TRUE(p.decoder->decode(enc->bytes).ok()) << i;
    }
    EXPECT_LT(p.encoder->canvasWidth(), 480);
    EXPECT_EQ(p.encoder->stats().reopens, 1);
}

// A layer that shrank inside its canvas (the canvas shrinks only after 30 such frames) costs about
// what it costs in a snug canvas: past the block its edge falls in the padding is the same in every
// frame, and crf follows the padding so x264 does not code the layer finer. With the layer's edge
// repeated across the whole margin and crf fixed, these P-frames cost 8.7× the snug ones.
TEST(X264Codec, PFramesOfALayerFarSmallerThanItsCanvasCostAboutWhatASnugCanvasCosts) {
    Pair snug = makePair();
    Pair padded = makePair();
    ASSERT_TRUE(padded.encoder->encode(detailedImage(480, 440, 0), false).ok());
    int64_t snug_bytes = 0;
    int64_t padded_bytes = 0;
    for (int i = 0; i < 20; ++i) {
        const ImageRgba8 src = detailedImage(200, 180, i * 2);
        auto a = snug.encoder->encode(src, false);
        auto b = padded.encoder->encode(src, false);
        ASSERT_TRUE(a.ok() && b.ok());
        ASSERT_FALSE(b->is_keyframe) << i;
        auto da = snug.decoder->decode(a->bytes);
        ASSERT_TRUE(da.ok()) << da.error();
        if (i >= 4) {  // both chains settled on the layer's content
            snug_bytes += static_cast<int64_t>(a->bytes.size());
            padded_bytes += static_cast<int64_t>(b->bytes.size());
        }
    }
    EXPECT_GE(padded.encoder->canvasWidth(), 480);
    EXPECT_LT(static_cast<double>(padded_bytes), 1.15 * static_cast<double>(snug_bytes))
        << padded_bytes << " bytes in the large canvas, " << snug_bytes << " in the snug one";
}

// The decoder converts a size swscale's fast kernel takes (even height, width a multiple of 16)
// out of the padded canvas and crops to the layer: the crop must be the layer, to its last row
// and column, as close to the source as an even-sized layer's.
TEST(X264Codec, AnOddSizedLayerDecodesToItsLastRowAndColumn) {
    for (auto [w, h] : {std::pair{270, 300}, std::pair{270, 301}, std::pair{271, 301}}) {
        Pair p = makePair();
        double worst_edge = 0.0;
        for (int i = 0; i < 4; ++i) {
            const ImageRgba8 src = detailedImage(w, h, i * 2);
            auto enc = p.encoder->encode(src, false);
            ASSERT_TRUE(enc.ok()) << enc.error();
            auto dec = p.decoder->decode(enc->bytes);
            ASSERT_TRUE(dec.ok()) << dec.error();
            ASSERT_EQ(dec->width(), w);
            ASSERT_EQ(dec->height(), h);
            EXPECT_GT(psnrRgb(src, *dec), kMinPsnrDb) << w << "x" << h << " frame " << i;
            // Mean absolute error over the last row and the last column.
            double sum = 0.0;
            int n = 0;
            for (int x = 0; x < w; ++x, ++n)
                for (int c = 0; c < 3; ++c)
                    sum += std::abs(int(src.at(x, h - 1, c)) - int(dec->at(x, h - 1, c))) / 3.0;
            for (int y = 0; y < h; ++y, ++n)
                for (int c = 0; c < 3; ++c)
                    sum += std::abs(int(src.at(w - 1, y, c)) - int(dec->at(w - 1, y, c))) / 3.0;
            worst_edge = std::max(worst_edge, sum / n);
        }
        EXPECT_LT(worst_edge, 12.0) << w << "x" << h;
    }
}

TEST_P(CodecBackends, GarbageBytesGiveAnErrorNeverACrash) {
    Pair p = makePair(config());
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> byte(0, 255);
    for (size_t len : {0, 1, 23, 24, 25, 200, 5000}) {
        std::vector<uint8_t> junk(len);
        for (auto& b : junk)
            b = static_cast<uint8_t>(byte(rng));
        auto dec = p.decoder->decode(junk);
        EXPECT_FALSE(dec.ok()) << len;
    }
    // Well-framed garbage (valid header and checksum): the codec itself must refuse it.
    for (bool key : {true, false}) {
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<uint8_t> junk(100 + static_cast<size_t>(trial) * 37);
            for (auto& b : junk)
                b = static_cast<uint8_t>(byte(rng));
            FrameHeader h;
            h.flags = key ? FrameHeader::kFlagKeyframe : 0;
            if (GetParam() == "raw")
                h.flags |= FrameHeader::kFlagRaw;
            h.frame_id = static_cast<uint32_t>(trial);
            h.width = 170;
            h.height = 190;
            auto dec = p.decoder->decode(packFrame(h, junk));
            EXPECT_FALSE(dec.ok()) << "key " << key << " trial " << trial;
        }
    }
}

TEST_P(CodecBackends, WellFramedGarbageMidStreamIsAnErrorAndAKeyframeRecovers) {
    Pair p = makePair(config());
    auto first = p.encoder->encode(detailedImage(170, 190), false);
    ASSERT_TRUE(first.ok());
    ASSERT_TRUE(p.decoder->decode(first->bytes).ok());
    std::mt19937 rng(9);
    std::uniform_int_distribution<int> byte(0, 255);
    std::vector<uint8_t> junk(3000);
    for (auto& b : junk)
        b = static_cast<uint8_t>(byte(rng));
    FrameHeader h;
    h.flags = GetParam() == "raw" ? FrameHeader::kFlagRaw : 0;
    h.frame_id = 1;
    h.width = 170;
    h.height = 190;
    EXPECT_FALSE(p.decoder->decode(packFrame(h, junk)).ok());
    EXPECT_TRUE(p.decoder->needsKeyframe());
    auto next = p.encoder->encode(detailedImage(170, 190, 1), false);  // frame 1, a P-frame
    ASSERT_TRUE(next.ok());
    EXPECT_FALSE(p.decoder->decode(next->bytes).ok());
    p.encoder->requestKeyframe();
    auto key = p.encoder->encode(detailedImage(170, 190, 2), false);
    ASSERT_TRUE(key.ok());
    EXPECT_TRUE(key->is_keyframe);
    auto dec = p.decoder->decode(key->bytes);
    ASSERT_TRUE(dec.ok()) << dec.error();
    EXPECT_GT(psnrRgb(detailedImage(170, 190, 2), *dec), kMinPsnrDb);
}

TEST(X264Codec, MutatedPayloadsWithValidFramingNeverCrash) {
    // Bit errors that a transport checksum missed (re-framed with a matching CRC) reach
    // libavcodec: each decode must end in an error or a picture of the right size.
    Pair p = makePair();
    std::vector<EncodedFrame> frames;
    for (int i = 0; i < 3; ++i) {
        auto enc = p.encoder->encode(detailedImage(170, 190, i * 3), false);
        ASSERT_TRUE(enc.ok());
        frames.push_back(std::move(enc).value());
    }
    std::mt19937 rng(17);
    int errors = 0;
    for (int trial = 0; trial < 300; ++trial) {
        auto decoder = makeVideoDecoder(CodecConfig{});
        ASSERT_TRUE(decoder.ok());
        const size_t target = static_cast<size_t>(trial) % frames.size();
        for (size_t f = 0; f <= target; ++f) {
            auto parsed = parseFrame(frames[f].bytes);
            ASSERT_TRUE(parsed.ok());
            std::vector<uint8_t> payload(parsed->payload.begin(), parsed->payload.end());
            if (f == target) {
                std::uniform_int_distribution<size_t> pos(0, payload.size() - 1);
                for (int k = 0; k < 1 + trial % 8; ++k)
                    payload[pos(rng)] ^= static_cast<uint8_t>(1u << (rng() % 8));
            }
            auto dec = (*decoder)->decode(packFrame(parsed->header, payload));
            if (f < target) {
                ASSERT_TRUE(dec.ok()) << dec.error();
            } else if (dec.ok()) {
                EXPECT_EQ(dec->width(), 170);
                EXPECT_EQ(dec->height(), 190);
            } else {
                ++errors;
                EXPECT_FALSE(dec.error().empty());
            }
        }
    }
    EXPECT_GT(errors, 0);
}

TEST_P(CodecBackends, TruncatedPacketsGiveAnError) {
    Pair p = makePair(config());
    auto enc = p.encoder->encode(detailedImage(170, 190), false);
    ASSERT_TRUE(enc.ok());
    const auto& bytes = enc->bytes;
    for (size_t keep : {size_t{0}, size_t{10}, FrameHeader::kSize, FrameHeader::kSize + 1,
                        bytes.size() / 2, bytes.size() - 1}) {
        std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<ptrdiff_t>(keep));
        auto dec = p.decoder->decode(cut);
        ASSERT_FALSE(dec.ok()) << keep;
    }
    // A truncated payload re-framed with a matching header and checksum reaches the codec.
    auto parsed = parseFrame(bytes);
    ASSERT_TRUE(parsed.ok());
    for (double fraction : {0.1, 0.5, 0.9}) {
        const auto n = static_cast<size_t>(static_cast<double>(parsed->payload.size()) * fraction);
        auto dec = p.decoder->decode(packFrame(parsed->header, parsed->payload.first(n)));
        EXPECT_FALSE(dec.ok()) << fraction;
    }
    auto whole = p.decoder->decode(bytes);
    EXPECT_TRUE(whole.ok()) << whole.error();
}

TEST_P(CodecBackends, PacketLostFromTheMiddleOfAGopIsReportedUntilAKeyframe) {
    Pair p = makePair(config());
    std::vector<EncodedFrame> frames;
    for (int i = 0; i < 8; ++i) {
        auto enc = p.encoder->encode(detailedImage(170, 190, i * 2), false);
        ASSERT_TRUE(enc.ok());
        frames.push_back(std::move(enc).value());
    }
    for (int i = 0; i < 4; ++i)
        ASSERT_TRUE(p.decoder->decode(frames[static_cast<size_t>(i)].bytes).ok()) << i;
    // Frame 4 is lost.
    auto after = p.decoder->decode(frames[5].bytes);
    ASSERT_FALSE(after.ok());
    EXPECT_THAT(after.error(), HasSubstr("lost"));
    EXPECT_TRUE(p.decoder->needsKeyframe());
    EXPECT_FALSE(p.decoder->decode(frames[6].bytes).ok());
    p.encoder->requestKeyframe();
    auto key = p.encoder->encode(detailedImage(170, 190, 20), false);
    ASSERT_TRUE(key.ok());
    EXPECT_TRUE(key->is_keyframe);
    ASSERT_TRUE(p.decoder->decode(key->bytes).ok());
    EXPECT_FALSE(p.decoder->needsKeyframe());
    auto follow = p.encoder->encode(detailedImage(170, 190, 22), false);
    ASSERT_TRUE(follow.ok());
    EXPECT_FALSE(follow->is_keyframe);
    auto dec = p.decoder->decode(follow->bytes);
    ASSERT_TRUE(dec.ok()) << dec.error();
    EXPECT_GT(psnrRgb(detailedImage(170, 190, 22), *dec), kMinPsnrDb);
}

TEST_P(CodecBackends, ADecoderJoiningMidStreamWaitsForAKeyframe) {
    Pair p = makePair(config());
    for (int i = 0; i < 3; ++i)
        ASSERT_TRUE(p.encoder->encode(detailedImage(170, 190, i), false).ok());
    auto late = makeVideoDecoder(config());
    ASSERT_TRUE(late.ok());
    auto mid = p.encoder->encode(detailedImage(170, 190, 3), false);
    ASSERT_TRUE(mid.ok());
    EXPECT_FALSE((*late)->decode(mid->bytes).ok());
    auto key = p.encoder->encode(detailedImage(170, 190, 4), true);
    ASSERT_TRUE(key.ok());
    EXPECT_TRUE(key->is_keyframe);
    EXPECT_TRUE((*late)->decode(key->bytes).ok());
}

TEST(X264Codec, FlatImageCostsFarFewerBytesThanNoise) {
    Pair flat = makePair();
    Pair noisy = makePair();
    size_t flat_bytes = 0;
    size_t noise_bytes = 0;
    for (int i = 0; i < 4; ++i) {
        auto f = flat.encoder->encode(flatImage(270, 300), false);
        auto n = noisy.encoder->encode(noiseImage(270, 300, static_cast<uint32_t>(i)), false);
        ASSERT_TRUE(f.ok() && n.ok());
        flat_bytes += f->bytes.size();
        noise_bytes += n->bytes.size();
    }
    EXPECT_LT(flat_bytes * 50, noise_bytes) << flat_bytes << " vs " << noise_bytes;
}

TEST(X264Codec, ReportsEncodeAndDecodeLatency) {
    Pair p = makePair();
    auto enc = p.encoder->encode(detailedImage(270, 300), false);
    ASSERT_TRUE(enc.ok());
    EXPECT_GT(enc->encode_ms, 0.0);
    EXPECT_LT(enc->encode_ms, 2000.0);
    ASSERT_TRUE(p.decoder->decode(enc->bytes).ok());
    EXPECT_GT(p.decoder->lastDecodeMs(), 0.0);
    EXPECT_LT(p.decoder->lastDecodeMs(), 2000.0);
}

TEST(X264Codec, LowerCrfSpendsMoreBytesForHigherQuality) {
    CodecConfig fine;
    fine.crf = 16;
    CodecConfig coarse;
    coarse.crf = 36;
    Pair a = makePair(fine);
    Pair b = makePair(coarse);
    const ImageRgba8 src = detailedImage(270, 300);
    auto ea = a.encoder->encode(src, false);
    auto eb = b.encoder->encode(src, false);
    ASSERT_TRUE(ea.ok() && eb.ok());
    EXPECT_GT(ea->bytes.size(), eb->bytes.size() * 2);
    auto da = a.decoder->decode(ea->bytes);
    auto db = b.decoder->decode(eb->bytes);
    ASSERT_TRUE(da.ok() && db.ok());
    EXPECT_GT(psnrRgb(src, *da), psnrRgb(src, *db) + 3.0);
}

TEST(X264Codec, BitrateModeKeepsPFramesNearTheBudget) {
    CodecConfig c;
    c.bitrate_bps = 2'000'000;  // 2 Mbit/s at 90 Hz: ~2.8 kB per frame
    Pair p = makePair(c);
    size_t p_bytes = 0;
    int p_frames = 0;
    for (int i = 0; i < 30; ++i) {
        auto enc = p.encoder->encode(detailedImage(270, 300, i * 4), false);
        ASSERT_TRUE(enc.ok());
        ASSERT_TRUE(p.decoder->decode(enc->bytes).ok());
        if (i >= 10) {
            p_bytes += enc->bytes.size();
            ++p_frames;
        }
    }
    const double per_frame = static_cast<double>(p_bytes) / p_frames;
    EXPECT_LT(per_frame, 2.0 * 2'000'000 / 8 / 90.0) << per_frame;
}

TEST(X264Codec, IntraRefreshHealsALossWithoutAKeyframe) {
    CodecConfig c;
    c.intra_refresh = true;
    c.keyint_frames = 10;
    Pair p = makePair(c);
    int healed_at = -1;
    for (int i = 0; i < 40; ++i) {
        const ImageRgba8 src = detailedImage(170, 190, i * 2);
        auto enc = p.encoder->encode(src, false);
        ASSERT_TRUE(enc.ok());
        if (i > 0) {
            EXPECT_FALSE(enc->is_keyframe) << "intra refresh sends no IDR after the first";
        }
        if (i == 5)
            continue;  // lost
        auto dec = p.decoder->decode(enc->bytes);
        EXPECT_FALSE(p.decoder->needsKeyframe());
        if (i > 5 && dec.ok() && healed_at < 0) {
            healed_at = i;
            EXPECT_GT(psnrRgb(src, *dec), kMinPsnrDb);
        }
        if (i < 5) {
            ASSERT_TRUE(dec.ok()) << dec.error();
        }
    }
    ASSERT_GT(healed_at, 5);
    EXPECT_LE(healed_at, 5 + c.keyint_frames + 2);
}

TEST(CodecConfig, RejectsOutOfRangeSettings) {
    auto bad = [](auto mutate) {
        CodecConfig c;
        mutate(c);
        return !validateCodecConfig(c).ok() && !makeVideoEncoder(c).ok() &&
               !makeVideoDecoder(c).ok();
    };
    EXPECT_TRUE(validateCodecConfig(CodecConfig{}).ok());
    EXPECT_TRUE(bad([](CodecConfig& c) { c.backend = "vp9"; }));
    EXPECT_TRUE(bad([](CodecConfig& c) { c.preset = "placebo"; }));
    EXPECT_TRUE(bad([](CodecConfig& c) { c.crf = 52; }));
    EXPECT_TRUE(bad([](CodecConfig& c) { c.slices = 0; }));
    EXPECT_TRUE(bad([](CodecConfig& c) { c.canvas_align_px = 15; }));
    EXPECT_TRUE(bad([](CodecConfig& c) {
        c.intra_refresh = true;
        c.keyint_frames = 0;
    }));
}

TEST_P(CodecBackends, RefusesLayersOutsideTheSizeRange) {
    Pair p = makePair(config());
    EXPECT_FALSE(p.encoder->encode(ImageRgba8(0, 0), false).ok());
    EXPECT_FALSE(p.encoder->encode(ImageRgba8(9000, 2), false).ok());
    EXPECT_TRUE(p.encoder->encode(detailedImage(3, 5), false).ok());
}

INSTANTIATE_TEST_SUITE_P(Backends, CodecBackends, ::testing::Values("x264", "raw"));

}  // namespace
}  // namespace qvr
