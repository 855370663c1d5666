#include "md3.h"

#include <cmath>
#include <cstring>
#include <numbers>

#include <fmt/format.h>

namespace qvr::detail {

namespace {

constexpr size_t kHeaderBytes = 108;
constexpr size_t kSurfaceHeaderBytes = 108;
constexpr size_t kShaderBytes = 68;  // name[64], index
constexpr size_t kTriangleBytes = 12;
constexpr size_t kUvBytes = 8;
constexpr size_t kVertexBytes = 8;  // int16 x, y, z (1/64 unit), packed normal
constexpr int kMd3Version = 15;
constexpr int kMaxSurfaces = 64;  // the game's MD3_MAX_SURFACES
constexpr float kXyzScale = 1.0f / 64.0f;

template <typename T>
T load(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

bool inside(std::span<const uint8_t> bytes, int64_t offset, int64_t count, size_t record) {
    return offset >= 0 && count >= 0 &&
           static_cast<uint64_t>(offset) + static_cast<uint64_t>(count) * record <= bytes.size();
}

// The game's packed normal: latitude and longitude bytes, each a turn in 256 steps.
glm::vec3 unpackNormal(uint16_t packed) {
    const float step = 2.0f * std::numbers::pi_v<float> / 255.0f;
    const float lat = static_cast<float>((packed >> 8) & 0xff) * step;
    const float lng = static_cast<float>(packed & 0xff) * step;
    return {std::cos(lat) * std::sin(lng), std::sin(lat) * std::sin(lng), std::cos(lng)};
}

Expected<Md3Surface> parseSurface(std::span<const uint8_t> s, int index) {
    if (s.size() < kSurfaceHeaderBytes)
        return makeError(fmt::format("surface {}: truncated header", index));
    const uint8_t* h = s.data();
    const int32_t n_shaders = load<int32_t>(h + 76), n_verts = load<int32_t>(h + 80),
                  n_tris = load<int32_t>(h + 84), ofs_tris = load<int32_t>(h + 88),
                  ofs_shaders = load<int32_t>(h + 92), ofs_uv = load<int32_t>(h + 96),
                  ofs_xyz = load<int32_t>(h + 100);
    if (n_verts < 0 || n_verts > kMaxMd3Vertices || n_tris < 0 || n_tris > 2 * kMaxMd3Vertices)
        return makeError(
            fmt::format("surface {}: {} vertices, {} triangles", index, n_verts, n_tris));
    if (!inside(s, ofs_tris, n_tris, kTriangleBytes) || !inside(s, ofs_uv, n_verts, kUvBytes) ||
        !inside(s, ofs_xyz, n_verts, kVertexBytes) ||
        !inside(s, ofs_shaders, n_shaders, kShaderBytes))
        return makeError(fmt::format("surface {}: a table runs past the surface", index));
    Md3Surface out;
    if (n_shaders > 0) {
        const char* name = reinterpret_cast<const char*>(s.data() + ofs_shaders);
        out.shader.assign(name, strnlen(name, 64));
    }
    for (int32_t v = 0; v < n_verts; ++v) {
        const uint8_t* p = s.data() + ofs_xyz + static_cast<size_t>(v) * kVertexBytes;
        out.positions.emplace_back(load<int16_t>(p) * kXyzScale, load<int16_t>(p + 2) * kXyzScale,
                                   load<int16_t>(p + 4) * kXyzScale);
        out.normals.push_back(unpackNormal(load<uint16_t>(p + 6)));
        const uint8_t* t = s.data() + ofs_uv + static_cast<size_t>(v) * kUvBytes;
        const glm::vec2 uv(load<float>(t), load<float>(t + 4));
        out.uvs.push_back(std::isfinite(uv.x) && std::isfinite(uv.y) ? uv : glm::vec2(0.0f));
    }
    for (int32_t k = 0; k < n_tris * 3; ++k) {
        const int32_t i = load<int32_t>(s.data() + ofs_tris + static_cast<size_t>(k) * 4);
        if (i < 0 || i >= n_verts)
            return makeError(fmt::format("surface {}: triangle index {} past its {} vertices",
                                         index, i, n_verts));
        out.indices.push_back(static_cast<uint32_t>(i));
    }
    return out;
}

}  // namespace

Expected<std::vector<Md3Surface>> parseMd3(std::span<const uint8_t> bytes) {
    if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), "IDP3", 4) != 0)
        return makeError("not an MD3 (no IDP3 header)");
    if (const int32_t version = load<int32_t>(bytes.data() + 4); version != kMd3Version)
        return makeError(fmt::format("MD3 version {} (Quake III's is {})", version, kMd3Version));
    const int32_t n_frames = load<int32_t>(bytes.data() + 76);
    const int32_t n_surfaces = load<int32_t>(bytes.data() + 84);
    int64_t offset = load<int32_t>(bytes.data() + 100);
    if (n_frames < 1 || n_surfaces < 0 || n_surfaces > kMaxSurfaces)
        return makeError(fmt::format("{} frames, {} surfaces", n_frames, n_surfaces));
    std::vector<Md3Surface> surfaces;
    for (int i = 0; i < n_surfaces; ++i) {
        if (!inside(bytes, offset, 1, kSurfaceHeaderBytes))
            return makeError(fmt::format("surface {} starts past the file", i));
        const int32_t end = load<int32_t>(bytes.data() + offset + 104);
        if (end < static_cast<int32_t>(kSurfaceHeaderBytes) || !inside(bytes, offset, end, 1))
            return makeError(fmt::format("surface {} ends past the file", i));
        auto s =
            parseSurface(bytes.subspan(static_cast<size_t>(offset), static_cast<size_t>(end)), i);
        if (!s)
            return makeError(s.error());
        surfaces.push_back(std::move(*s));
        offset += end;
    }
    return surfaces;
}

}  // namespace qvr::detail
