// The codec backends behind makeVideoEncoder/makeVideoDecoder (paper §3.2).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include <fmt/format.h>

#include "qvr/codec/frame_header.h"
#include "qvr/codec/video_codec.h"
#include "qvr/core/clock.h"

namespace qvr::detail {

std::unique_ptr<VideoEncoder> makeRawEncoder(const CodecConfig& config);
std::unique_ptr<VideoDecoder> makeRawDecoder();
Expected<std::unique_ptr<VideoEncoder>> makeX264Encoder(const CodecConfig& config);
Expected<std::unique_ptr<VideoDecoder>> makeH264Decoder();

// A decoder of one kind of framed stream (raw frames, or coded ones): decode() parses a frame,
// refuses the other kind, has the stream's reference tracker admit it (key frames always pass,
// so decodePayload may still refuse one), and times what decodePayload makes of its payload.
// decodePayload reports each admitted frame's outcome to tracker().
class FramedDecoder : public VideoDecoder {
public:
    Expected<ImageRgba8> decode(std::span<const uint8_t> bytes) final {
        const Stopwatch t0;
        auto parsed = parseFrame(bytes);
        if (!parsed)
            return makeError(parsed.error());
        const FrameHeader& h = parsed->header;
        if (((h.flags & FrameHeader::kFlagRaw) != 0) != m_raw)
            return makeError(fmt::format("{}: frame {} is {}a raw frame", m_name, h.frame_id,
                                         m_raw ? "not " : ""));
        if (Status s = m_tracker.admit(h); !s)
            return makeError(s.error());
        auto image = decodePayload(h, parsed->payload);
        if (image)
            m_last_ms = t0.elapsedMs();
        return image;
    }
    bool needsKeyframe() const final { return m_tracker.needsKeyframe(); }
    double lastDecodeMs() const final { return m_last_ms; }

protected:
    // `name` starts the decoder's messages ("raw decoder: …").
    FramedDecoder(bool raw, std::string_view name) : m_raw(raw), m_name(name) {}
    virtual Expected<ImageRgba8> decodePayload(const FrameHeader& h,
                                               std::span<const uint8_t> payload) = 0;
    ReferenceTracker& tracker() { return m_tracker; }

private:
    bool m_raw;
    std::string_view m_name;
    ReferenceTracker m_tracker;
    double m_last_ms = 0.0;
};

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
