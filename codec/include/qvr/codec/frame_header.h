// The small header in front of every encoded layer frame (paper §3.2 streams each periphery
// layer separately): the layer's real size inside the coded canvas, the frame id that exposes
// losses, and a checksum that exposes truncation and corruption before the codec sees the bytes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr {

// Wire layout, little-endian, 28 bytes:
//   0  u32 magic "QVRF"      4  u8 version (2)    5  u8 flags (bit 0 key frame, bit 1 raw,
//                                                  bit 2 the encoder opened a new canvas)
//   6  u16 refresh_frames (intra-refresh period, 0 = IDR-based recovery)
//   8  u32 frame_id          12 u16 width        14 u16 height   (the layer's real size)
//  16  u32 payload_bytes     20 u32 CRC-32 (IEEE) of the payload
//  24  u32 server_us: the server's time on the frame when this layer left its encoder, from
//      when it started on the frame (0: not said); stamped after encoding, outside the CRC
struct FrameHeader {
    static constexpr uint32_t kMagic = 0x46525651u;  // "QVRF" read as little-endian u32
    static constexpr uint8_t kVersion = 2;
    static constexpr size_t kSize = 28;
    static constexpr uint8_t kFlagKeyframe = 1;
    static constexpr uint8_t kFlagRaw = 2;
    // The encoder (re)opened for this frame: a stream's first frame, or a canvas that grew or
    // shrank (core/canvas_policy.h); its key frame is the cost of an e1 move, maybe a late one.
    static constexpr uint8_t kFlagNewCanvas = 4;

    uint8_t flags = 0;
    uint16_t refresh_frames = 0;
    uint32_t frame_id = 0;
    uint16_t width = 0;
    uint16_t height = 0;
    uint32_t payload_bytes = 0;
    uint32_t crc32 = 0;
    uint32_t server_us = 0;

    bool keyframe() const { return (flags & kFlagKeyframe) != 0; }
    bool newCanvas() const { return (flags & kFlagNewCanvas) != 0; }
};

uint32_t crc32Ieee(std::span<const uint8_t> bytes);

// Appends the header for `payload` (filling payload_bytes and crc32) and then the payload.
std::vector<uint8_t> packFrame(FrameHeader header, std::span<const uint8_t> payload);

struct ParsedFrame {
    FrameHeader header;
    std::span<const uint8_t> payload;
};
// Validates magic, version, sizes and checksum; the payload span points into `bytes`.
Expected<ParsedFrame> parseFrame(std::span<const uint8_t> bytes);
// The flags of a frame a decoder took (after parseFrame accepted it); 0 for bytes too short to
// hold a header.
uint8_t frameFlags(std::span<const uint8_t> bytes);
// The server's time on the frame (FrameHeader::server_us) of a packed frame, in place, and read
// back; 0 for bytes too short to hold a header. The headset's LIWC learns the server's part of
// T_remote from it (docs/LIWC.md).
void stampServerUs(std::vector<uint8_t>& frame, uint32_t server_us);
uint32_t frameServerUs(std::span<const uint8_t> bytes);

// Tracks the reference chain of one stream on the receiving side: a non-key frame is decodable
// only if the frame before it was. Shared by every decoder so they agree on loss semantics.
class ReferenceTracker {
public:
    // Decides whether a frame may be decoded; on refusal returns the reason.
    Status admit(const FrameHeader& header);
    // Records the outcome of decoding an admitted frame.
    void decoded(const FrameHeader& header, bool success);
    bool needsKeyframe() const { return m_state == State::kNeedKeyframe; }
    // In intra-refresh streams: frames still to pass before pictures are trustworthy again.
    int recoveringFrames() const { return m_recover_left; }
    // True when the last decoded frame's picture should be withheld (refresh wave incomplete).
    bool withholdPicture() const { return m_state == State::kRecovering; }

private:
    enum class State { kNeedKeyframe, kOk, kRecovering };
    State m_state = State::kNeedKeyframe;
    bool m_seen_any = false;
    uint32_t m_last_id = 0;
    int m_recover_left = 0;
};

// True if the Annex B byte stream holds an IDR slice (NAL unit type 5).
bool annexBHasIdr(std::span<const uint8_t> annexb);

}  // namespace qvr
