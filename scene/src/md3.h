// Quake III MD3 models (IDP3 version 15): the first frame of every surface, for the item
// models a level's entities place. The bytes are untrusted: every count, offset and index is
// checked before use.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "qvr/core/expected.h"

namespace qvr::detail {

struct Md3Surface {
    std::string shader;                // the surface's first shader: an image path
    std::vector<glm::vec3> positions;  // Quake units, model space, frame 0
    std::vector<glm::vec3> normals;    // unit, model space
    std::vector<glm::vec2> uvs;
    std::vector<uint32_t> indices;  // triangles into positions
};

// Surfaces larger than this are rejected (the game's SHADER_MAX_VERTEXES is 1000; MD3s stay
// far below).
inline constexpr int kMaxMd3Vertices = 65536;

Expected<std::vector<Md3Surface>> parseMd3(std::span<const uint8_t> bytes);

}  // namespace qvr::detail
