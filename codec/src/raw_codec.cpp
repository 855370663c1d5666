// The fake codec (STYLE.md §4): raw RGBA in the same framing and with the same key-frame and
// loss semantics as x264, so runtime logic (paper Fig. 4) is testable without FFmpeg.
#include <cstring>

#include <fmt/format.h>

#include "backends.h"
#include "qvr/codec/frame_header.h"
#include "qvr/core/clock.h"

namespace qvr::detail {

namespace {

class RawEncoder final : public VideoEncoder {
public:
    explicit RawEncoder(const CodecConfig& config) : m_config(config) {}

    Expected<EncodedFrame> encode(const ImageRgba8& image, bool force_keyframe) override {
        const Stopwatch t0;
        if (image.width() < 1 || image.height() < 1 || image.width() > m_config.max_side_px ||
            image.height() > m_config.max_side_px)
            return makeError(fmt::format("raw encoder: layer size {}x{} outside [1, {}]",
                                         image.width(), image.height(), m_config.max_side_px));
        // A size change is a new stream for a raw decoder too: key frame, like x264's reopen.
        const bool resized = image.width() != m_width || image.height() != m_height;
        const bool key = force_keyframe || m_force_key || resized ||
                         (m_config.keyint_frames > 0 && m_since_key >= m_config.keyint_frames);
        FrameHeader h;
        h.flags = FrameHeader::kFlagRaw | (key ? FrameHeader::kFlagKeyframe : 0);
        h.frame_id = m_next_id++;
        h.width = static_cast<uint16_t>(image.width());
        h.height = static_cast<uint16_t>(image.height());
        EncodedFrame out =
            packEncodedFrame(h, std::span<const uint8_t>(image.data(), image.sizeBytes()), m_stats);
        if (resized && m_width != 0)
            ++m_stats.reopens;
        m_width = image.width();
        m_height = image.height();
        m_force_key = false;
        m_since_key = key ? 1 : m_since_key + 1;
        out.encode_ms = t0.elapsedMs();
        return out;
    }
    void requestKeyframe() override { m_force_key = true; }
    const EncoderStats& stats() const override { return m_stats; }
    int canvasWidth() const override { return m_width; }
    int canvasHeight() const override { return m_height; }

private:
    CodecConfig m_config;
    EncoderStats m_stats;
    uint32_t m_next_id = 0;
    bool m_force_key = true;
    int m_since_key = 0;
    int m_width = 0;
    int m_height = 0;
};

class RawDecoder final : public FramedDecoder {
public:
    RawDecoder() : FramedDecoder(true, "raw decoder") {}

private:
    Expected<ImageRgba8> decodePayload(const FrameHeader& h,
                                       std::span<const uint8_t> payload) override {
        const size_t want = size_t{h.width} * h.height * 4;
        if (payload.size() != want) {
            tracker().decoded(h, false);
            return makeError(
                fmt::format("raw decoder: frame {} has {} payload bytes, {}x{} RGBA "
                            "needs {}",
                            h.frame_id, payload.size(), h.width, h.height, want));
        }
        tracker().decoded(h, true);
        ImageRgba8 image(h.width, h.height);
        std::memcpy(image.data(), payload.data(), want);
        return image;
    }
};

}  // namespace

std::unique_ptr<VideoEncoder> makeRawEncoder(const CodecConfig& config) {
    return std::make_unique<RawEncoder>(config);
}
std::unique_ptr<VideoDecoder> makeRawDecoder() {
    return std::make_unique<RawDecoder>();
}

}  // namespace qvr::detail
