// Texture decoding for the loaders: JPEG, TGA and PNG bytes to RGBA8 through stb_image, with
// a size cap and power-of-two box down-sampling so a level's textures stay within memory.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/scene/scene.h"

namespace qvr {

inline constexpr int kMaxDecodedImageSide = 8192;

// Decodes bytes; halves the image (2×2 box filter) until neither side exceeds max_side_px.
Expected<SceneTexture> decodeImage(std::span<const uint8_t> bytes, const std::string& name,
                                   int max_side_px);

// Halves width and height (odd sizes drop the last row/column), averaging 2×2 blocks.
void halveTexture(SceneTexture& t);

}  // namespace qvr
