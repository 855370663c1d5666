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
// Pixels an image may decode to (4096², 64 MB of RGBA; game textures are 2048² at most). A
// compressed image's header can claim 8192² with a few dozen bytes (stb_image fills what the
// data does not hold), and decoding it took 256 MB and seconds per texture (found by bsp_fuzz:
// a 34-byte TGA).
inline constexpr int64_t kMaxDecodedImagePixels = int64_t{4096} * 4096;

// Decodes bytes; halves the image (2×2 box filter) until neither side exceeds max_side_px.
Expected<SceneTexture> decodeImage(std::span<const uint8_t> bytes, const std::string& name,
                                   int max_side_px);

// Halves width and height (odd sizes drop the last row/column), averaging 2×2 blocks.
void halveTexture(SceneTexture& t);

}  // namespace qvr
