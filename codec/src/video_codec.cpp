// Codec factory and config checks for the layer streams (paper §3.2).
#include "qvr/codec/video_codec.h"

#include <fmt/format.h>

#include "backends.h"

namespace qvr {

Status validateCodecConfig(const CodecConfig& c) {
    if (c.backend != "x264" && c.backend != "raw")
        return makeError(fmt::format("codec backend '{}': expected x264 or raw", c.backend));
    if (c.preset != "ultrafast" && c.preset != "superfast" && c.preset != "veryfast" &&
        c.preset != "faster" && c.preset != "fast" && c.preset != "medium")
        return makeError(
            fmt::format("codec preset '{}': expected ultrafast, superfast, "
                        "veryfast, faster, fast or medium",
                        c.preset));
    if (c.crf < 0 || c.crf > 51)
        return makeError(fmt::format("codec crf {} outside [0, 51]", c.crf));
    if (c.bitrate_bps < 0 || c.bitrate_bps > int64_t{1'000'000'000})
        return makeError(fmt::format("codec bitrate {} bps outside [0, 1e9]", c.bitrate_bps));
    if (!(c.frame_rate_hz >= 1.0 && c.frame_rate_hz <= 1000.0))
        return makeError(fmt::format("codec frame rate {} Hz outside [1, 1000]", c.frame_rate_hz));
    if (c.keyint_frames < 0 || c.keyint_frames > 65535)
        return makeError(fmt::format("codec keyint {} outside [0, 65535]", c.keyint_frames));
    if (c.intra_refresh && c.keyint_frames < 2)
        return makeError("codec intra refresh needs keyint_frames >= 2 (the refresh period)");
    if (c.slices < 1 || c.slices > 32)
        return makeError(fmt::format("codec slices {} outside [1, 32]", c.slices));
    if (c.threads < 1 || c.threads > 64)
        return makeError(fmt::format("codec threads {} outside [1, 64]", c.threads));
    if (c.canvas_align_px < 2 || c.canvas_align_px > 256 || c.canvas_align_px % 2 != 0)
        return makeError(
            fmt::format("codec canvas alignment {} must be even, in [2, 256]", c.canvas_align_px));
    if (!(c.canvas_headroom >= 0.0 && c.canvas_headroom <= 1.0))
        return makeError(fmt::format("codec canvas headroom {} outside [0, 1]", c.canvas_headroom));
    if (!(c.canvas_shrink_ratio >= 0.0 && c.canvas_shrink_ratio <= 1.0))
        return makeError(
            fmt::format("codec canvas shrink ratio {} outside [0, 1]", c.canvas_shrink_ratio));
    if (c.canvas_shrink_after_frames < 1)
        return makeError("codec canvas_shrink_after_frames must be >= 1");
    if (c.max_side_px < c.canvas_align_px || c.max_side_px > 16384)
        return makeError(
            fmt::format("codec max side {} outside [alignment, 16384]", c.max_side_px));
    return Status::success();
}

Expected<std::unique_ptr<VideoEncoder>> makeVideoEncoder(const CodecConfig& config) {
    if (Status s = validateCodecConfig(config); !s)
        return makeError(s.error());
    if (config.backend == "raw")
        return detail::makeRawEncoder(config);
    return detail::makeX264Encoder(config);
}

Expected<std::unique_ptr<VideoDecoder>> makeVideoDecoder(const CodecConfig& config) {
    if (Status s = validateCodecConfig(config); !s)
        return makeError(s.error());
    if (config.backend == "raw")
        return detail::makeRawDecoder();
    return detail::makeH264Decoder();
}

}  // namespace qvr
