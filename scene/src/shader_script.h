// Quake III shader scripts (scripts/*.shader): which image a shader name draws with when the
// name itself is not an image file, e.g. "textures/base_floor/proto_grate" → its first "map".
#pragma once

#include <string>
#include <string_view>
#include <unordered_map>

#include "qvr/scene/pk3.h"

namespace qvr {

class ShaderLibrary {
public:
    // Reads every scripts/*.shader of files; unreadable or malformed scripts are skipped
    // from the point of the error on (the game does the same).
    void load(const GameFileSystem& files);
    // Adds the shaders of one script's text.
    void parse(std::string_view text);
    // The normalized image path (without extension) of the shader's first texture stage, or
    // "" when the shader is unknown or has none.
    std::string imageFor(const std::string& shader_name) const;
    size_t size() const { return m_images.size(); }

private:
    std::unordered_map<std::string, std::string> m_images;
};

// Strips a trailing ".tga"/".jpg"/".png" (any case).
std::string stripImageExtension(std::string path);

}  // namespace qvr
