// The encoder/decoder seam between the render server and the headset (paper §3.2, Fig. 7): each
// periphery layer of each eye is its own video stream whose frame size follows e1 frame to frame.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"

namespace qvr {

// One encoded layer image as it goes on the wire: a FrameHeader (frame_header.h) followed by the
// codec's payload. `bytes` is everything a decoder needs; the other fields are for the sender.
struct EncodedFrame {
    std::vector<uint8_t> bytes;
    bool is_keyframe = false;  // decodable without any earlier frame (an H.264 IDR)
    uint32_t frame_id = 0;     // consecutive per stream; a gap tells the decoder a frame was lost
    double encode_ms = 0.0;    // wall time of encode(), colour conversion included
};

// Low-latency H.264 settings (docs/CODEC.md). Defaults suit one periphery layer at 90 Hz.
struct CodecConfig {
    std::string backend = "x264";      // "x264" (libavcodec + libx264) or "raw" (the fake)
    std::string preset = "ultrafast";  // x264 preset: ultrafast or superfast for real time
    int crf = 23;                 // constant quality (0 best … 51 worst) when bitrate_bps == 0
    int64_t bitrate_bps = 0;      // > 0: ABR with a one-frame VBV instead of CRF
    double frame_rate_hz = 90.0;  // for rate control only; no timing is enforced
    int keyint_frames = 120;      // periodic IDR (or intra-refresh wave) distance; 0 = never
    bool intra_refresh = false;   // a moving intra column instead of periodic IDRs: smooth bitrate
    int slices = 1;               // slices per frame (more: error resilience, sliced threads)
    int threads = 1;              // x264 sliced threads; 1 keeps cores for the renderer
    // Canvas policy (docs/CODEC.md): the encoder codes into a canvas at least as large as the
    // layer, so a layer that changes size frame to frame does not force an IDR every frame.
    int canvas_align_px = 16;             // canvas sides are multiples of this (macroblocks)
    double canvas_headroom = 0.10;        // grow to 10% more than needed so small growth fits
    double canvas_shrink_ratio = 0.5;     // shrink when the layer covers less than this fraction
    int canvas_shrink_after_frames = 30;  // … for this many consecutive frames
    int max_side_px = 8192;
};

struct EncoderStats {
    int64_t frames = 0;
    int64_t keyframes = 0;
    int64_t reopens = 0;  // canvas changes (each costs an IDR)
    int64_t bytes = 0;
};

class VideoEncoder {
public:
    virtual ~VideoEncoder() = default;
    // Encodes one layer image (any size from 2×2 up to max_side_px). Never throws; an error
    // (bad size, codec failure) leaves the encoder usable for the next frame.
    virtual Expected<EncodedFrame> encode(const ImageRgba8& image, bool force_keyframe = false) = 0;
    // Makes the next encoded frame a key frame: the sender's answer to a decoder reporting loss.
    virtual void requestKeyframe() = 0;
    virtual const EncoderStats& stats() const = 0;
    // Canvas the stream currently codes into (0×0 before the first frame).
    virtual int canvasWidth() const = 0;
    virtual int canvasHeight() const = 0;
};

class VideoDecoder {
public:
    virtual ~VideoDecoder() = default;
    // Decodes one frame's bytes to the layer image at its real size. Garbage, truncated or
    // corrupted bytes, and a frame whose reference was lost, give an error, never a crash; after
    // a loss every frame is refused until a key frame arrives (or, in intra-refresh streams,
    // until a refresh wave has passed). needsKeyframe() tells the receiver to ask the sender.
    virtual Expected<ImageRgba8> decode(std::span<const uint8_t> bytes) = 0;
    virtual bool needsKeyframe() const = 0;
    virtual double lastDecodeMs() const = 0;
};

Expected<std::unique_ptr<VideoEncoder>> makeVideoEncoder(const CodecConfig& config);
Expected<std::unique_ptr<VideoDecoder>> makeVideoDecoder(const CodecConfig& config);

// Checks a config's ranges; the factories call it.
Status validateCodecConfig(const CodecConfig& config);

}  // namespace qvr
