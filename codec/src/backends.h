// The codec backends behind makeVideoEncoder/makeVideoDecoder (paper §3.2).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include <fmt/format.h>

#include "qvr/codec/frame_header.h"
#include "qvr/codec/video_codec.h"

namespace qvr::detail {

std::unique_ptr<VideoEncoder> makeRawEncoder(const CodecConfig& config);
std::unique_ptr<VideoDecoder> makeRawDecoder();
Expected<std::unique_ptr<VideoEncoder>> makeX264Encoder(const CodecConfig& config);
Expected<std::unique_ptr<VideoDecoder>> makeH264Decoder();

// A frame for a decoder of raw frames (`raw`) or of coded ones: parsed, refused when it is the
// other kind, then admitted by the stream's reference tracker (which leaves key frames as they
// are, so a decoder may still refuse a key frame after this). `decoder` names the decoder in the
// message.
inline Expected<ParsedFrame> admitFrameFor(std::span<const uint8_t> bytes, bool raw,
                                           std::string_view decoder, ReferenceTracker& tracker) {
    auto parsed = parseFrame(bytes);
    if (!parsed)
        return makeError(parsed.error());
    const FrameHeader& h = parsed->header;
    if (((h.flags & FrameHeader::kFlagRaw) != 0) != raw)
        return makeError(
            fmt::format("{}: frame {} is {}a raw frame", decoder, h.frame_id, raw ? "not " : ""));
    if (Status s = tracker.admit(h); !s)
        return makeError(s.error());
    return parsed;
}

// One coded frame behind its header, counted in the encoder's stats (the caller times it).
inline EncodedFrame packEncodedFrame(const FrameHeader& h, std::span<const uint8_t> payload,
                                     EncoderStats& stats) {
    EncodedFrame out;
    out.bytes = packFrame(h, payload);
    out.is_keyframe = h.keyframe();
    out.frame_id = h.frame_id;
    ++stats.frames;
    stats.keyframes += out.is_keyframe ? 1 : 0;
    stats.bytes += static_cast<int64_t>(out.bytes.size());
    return out;
}

}  // namespace qvr::detail
