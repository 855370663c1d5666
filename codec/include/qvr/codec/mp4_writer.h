// A video file a browser plays: RGBA frames encoded with libx264 (yuv420p, High profile) and
// muxed as MP4 by libavformat, moov atom first so playback starts before the file has loaded.
// Used for the display video of `qvr run` (docs/RUNTIME.md); not on any per-frame path.
#pragma once

#include <memory>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"

namespace qvr {

class Mp4Writer {
public:
    // Opens `path` for frames of width×height (both even, 16..8192) at `fps` (1..1000).
    static Expected<std::unique_ptr<Mp4Writer>> open(const std::string& path, int width, int height,
                                                     int fps, int crf = 20);
    virtual ~Mp4Writer() = default;
    // Encodes one frame; it must have the size given to open().
    virtual Status write(const ImageRgba8& frame) = 0;
    // Flushes the encoder and writes the index. Without it the file is not playable.
    virtual Status finish() = 0;
};

// What ffprobe would say about a video file, read through libavformat: container, codec, size,
// and the frames counted by reading every packet of the first video stream.
struct VideoFileInfo {
    std::string format_name;  // libavformat's demuxer name, e.g. "mov,mp4,m4a,3gp,3g2,mj2"
    std::string codec_name;   // e.g. "h264"
    std::string profile;      // e.g. "High"
    int width = 0;
    int height = 0;
    double fps = 0.0;
    int64_t frames = 0;
    int64_t key_frames = 0;
};
Expected<VideoFileInfo> probeVideoFile(const std::string& path);

}  // namespace qvr
