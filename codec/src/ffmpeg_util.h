// What the codec's FFmpeg users (the x264 backend, the MP4 writer and reader) share: FFmpeg's
// error codes and text, and its log kept quiet.
#pragma once

#include <mutex>
#include <string>

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

namespace qvr::detail {

// FFmpeg's error macros expand to C casts; compute them once here with the warning silenced.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
inline constexpr int kAvErrorEagain = AVERROR(EAGAIN);
inline constexpr int kAvErrorEof = AVERROR_EOF;
#pragma GCC diagnostic pop

inline std::string avErrorText(int err) {
    char buf[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(err, buf, sizeof(buf));
    return buf;
}

// libavcodec logs every bitstream error at ERROR level; decoding untrusted bytes would flood
// stderr, and every error already reaches the caller as an Expected. Process-wide, set once.
inline void quietFfmpegLog() {
    static std::once_flag once;
    std::call_once(once, [] { av_log_set_level(AV_LOG_FATAL); });
}

}  // namespace qvr::detail
