// The codec backends behind makeVideoEncoder/makeVideoDecoder (paper §3.2).
#pragma once

#include <memory>

#include "qvr/codec/video_codec.h"

namespace qvr::detail {

std::unique_ptr<VideoEncoder> makeRawEncoder(const CodecConfig& config);
std::unique_ptr<VideoDecoder> makeRawDecoder();
Expected<std::unique_ptr<VideoEncoder>> makeX264Encoder(const CodecConfig& config);
Expected<std::unique_ptr<VideoDecoder>> makeH264Decoder();

}  // namespace qvr::detail
