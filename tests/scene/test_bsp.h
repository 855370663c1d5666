// Writes small IBSP 46 files byte by byte for the loader tests, so every field's position is
// spelled out independently of the parser.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace qvr::test {

struct BspShader {
    std::string name;
    int32_t surface_flags = 0;
    int32_t content_flags = 1;
};

struct BspVertex {
    float xyz[3] = {0, 0, 0};
    float st[2] = {0, 0};
    float lm[2] = {0, 0};
    float normal[3] = {0, 0, 1};
    uint8_t rgba[4] = {255, 255, 255, 255};
};

struct BspFace {
    int32_t shader = 0;
    int32_t fog = -1;
    int32_t type = 1;
    int32_t first_vertex = 0;
    int32_t vertex_count = 0;
    int32_t first_index = 0;
    int32_t index_count = 0;
    int32_t lightmap = -1;
    int32_t patch_width = 0;
    int32_t patch_height = 0;
};

inline constexpr int kBspLumpEntities = 0;
inline constexpr int kBspLumpShaders = 1;
inline constexpr int kBspLumpVertices = 10;
inline constexpr int kBspLumpMeshIndices = 11;
inline constexpr int kBspLumpFaces = 13;
inline constexpr int kBspLumpLightmaps = 14;
inline constexpr size_t kBspFaceBytes = 104;
inline constexpr size_t kBspVertexBytes = 44;

struct TestBsp {
    std::string entities;
    std::vector<BspShader> shaders;
    std::vector<BspVertex> vertices;
    std::vector<int32_t> mesh_indices;
    std::vector<BspFace> faces;
    std::vector<std::vector<uint8_t>> lightmaps;  // 128·128·3 bytes each

    // Header, then the lumps in order 0…16 (unused ones empty, at the end of the file).
    std::vector<uint8_t> bytes() const {
        std::vector<uint8_t> lumps[17];
        lumps[kBspLumpEntities].assign(entities.begin(), entities.end());
        lumps[kBspLumpEntities].push_back(0);
        for (const auto& s : shaders) {
            std::vector<uint8_t> rec(72, 0);
            std::memcpy(rec.data(), s.name.data(), std::min<size_t>(s.name.size(), 63));
            std::memcpy(rec.data() + 64, &s.surface_flags, 4);
            std::memcpy(rec.data() + 68, &s.content_flags, 4);
            append(lumps[kBspLumpShaders], rec);
        }
        for (const auto& v : vertices) {
            std::vector<uint8_t> rec(kBspVertexBytes, 0);
            std::memcpy(rec.data(), v.xyz, 12);
            std::memcpy(rec.data() + 12, v.st, 8);
            std::memcpy(rec.data() + 20, v.lm, 8);
            std::memcpy(rec.data() + 28, v.normal, 12);
            std::memcpy(rec.data() + 40, v.rgba, 4);
            append(lumps[kBspLumpVertices], rec);
        }
        for (int32_t i : mesh_indices)
            appendInt(lumps[kBspLumpMeshIndices], i);
        for (const auto& f : faces) {
            std::vector<uint8_t> rec(kBspFaceBytes, 0);
            const int32_t head[8] = {f.shader,       f.fog,         f.type,        f.first_vertex,
                                     f.vertex_count, f.first_index, f.index_count, f.lightmap};
            std::memcpy(rec.data(), head, sizeof(head));
            std::memcpy(rec.data() + 96, &f.patch_width, 4);
            std::memcpy(rec.data() + 100, &f.patch_height, 4);
            append(lumps[kBspLumpFaces], rec);
        }
        for (const auto& lm : lightmaps)
            append(lumps[kBspLumpLightmaps], lm);
        std::vector<uint8_t> out = {'I', 'B', 'S', 'P'};
        appendInt(out, 46);
        int32_t offset = 8 + 17 * 8;
        for (const auto& l : lumps) {
            appendInt(out, offset);
            appendInt(out, static_cast<int32_t>(l.size()));
            offset += static_cast<int32_t>(l.size());
        }
        for (const auto& l : lumps)
            append(out, l);
        return out;
    }

    static void append(std::vector<uint8_t>& out, const std::vector<uint8_t>& more) {
        out.insert(out.end(), more.begin(), more.end());
    }
    static void appendInt(std::vector<uint8_t>& out, int32_t v) {
        const size_t at = out.size();
        out.resize(at + 4);
        std::memcpy(out.data() + at, &v, 4);
    }
};

inline void putInt(std::vector<uint8_t>& bytes, size_t at, int32_t v) {
    std::memcpy(bytes.data() + at, &v, 4);
}
inline int32_t getInt(const std::vector<uint8_t>& bytes, size_t at) {
    int32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
}
// Byte offset of lump i's {offset, length} in the header.
inline size_t lumpDirectoryAt(int lump) {
    return 8 + 8 * static_cast<size_t>(lump);
}

// A level with: a 64×64-unit floor quad (polygon face, 2 triangles, wound clockwise seen from
// +z as Quake III fronts are), a one-triangle mesh face, a 3×3 Bézier patch, a sky face, a face
// whose shader index is out of range, one lightmap and three entities (two spawns).
inline TestBsp makeSampleBsp() {
    TestBsp b;
    b.entities =
        "{\n\"classname\" \"worldspawn\"\n\"message\" \"test level\"\n}\n"
        "{\n\"classname\" \"info_player_deathmatch\"\n\"origin\" \"64 128 32\"\n\"angle\" "
        "\"90\"\n}\n"
        "{\n\"classname\" \"info_player_start\"\n\"origin\" \"-10 0 0\"\n}\n";
    b.shaders = {{"textures/test/wall", 0, 1},
                 {"textures/test/scripted", 0, 1},
                 {"textures/skies/sky", 0x4, 0}};
    auto vert = [](float x, float y, float z, float s, float t) {
        BspVertex v;
        v.xyz[0] = x;
        v.xyz[1] = y;
        v.xyz[2] = z;
        v.st[0] = s;
        v.st[1] = t;
        v.lm[0] = s;
        v.lm[1] = t;
        return v;
    };
    // Floor quad, vertices 0–3.
    b.vertices = {vert(0, 0, 0, 0, 0), vert(64, 0, 0, 1, 0), vert(64, 64, 0, 1, 1),
                  vert(0, 64, 0, 0, 1)};
    b.mesh_indices = {0, 2, 1, 0, 3, 2};
    b.faces.push_back({0, -1, 1, 0, 4, 0, 6, 0, 0, 0});
    // Mesh face: one triangle, vertices 4–6, indices 6–8.
    b.vertices.push_back(vert(0, 0, 64, 0, 0));
    b.vertices.push_back(vert(0, 64, 64, 0, 1));
    b.vertices.push_back(vert(64, 0, 64, 1, 0));
    b.mesh_indices.insert(b.mesh_indices.end(), {0, 1, 2});
    b.faces.push_back({1, -1, 3, 4, 3, 6, 3, -1, 0, 0});
    // Patch: a 3×3 control grid bulging up, vertices 7–15.
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            b.vertices.push_back(vert(128.0f + 32.0f * i, 32.0f * j,
                                      (i == 1 && j == 1) ? 32.0f : 0.0f, 0.5f * i, 0.5f * j));
    b.faces.push_back({0, -1, 2, 7, 9, 0, 0, 0, 3, 3});
    // Sky face reusing the floor quad, and a face with a shader index past the shader lump.
    b.faces.push_back({2, -1, 1, 0, 4, 0, 6, -1, 0, 0});
    b.faces.push_back({7, -1, 1, 0, 4, 0, 6, -1, 0, 0});
    std::vector<uint8_t> lm(128 * 128 * 3, 16);
    lm[0] = 10;
    lm[1] = 20;
    lm[2] = 200;
    b.lightmaps.push_back(lm);
    return b;
}

// An uncompressed 32-bit TGA, rows stored top to bottom (descriptor bit 5).
inline std::vector<uint8_t> makeTga(int w, int h, const std::vector<uint8_t>& rgba) {
    std::vector<uint8_t> out(18, 0);
    out[2] = 2;  // uncompressed true colour
    out[12] = static_cast<uint8_t>(w & 0xff);
    out[13] = static_cast<uint8_t>(w >> 8);
    out[14] = static_cast<uint8_t>(h & 0xff);
    out[15] = static_cast<uint8_t>(h >> 8);
    out[16] = 32;
    out[17] = 0x28;  // top-left origin, 8 alpha bits
    for (size_t i = 0; i + 3 < rgba.size(); i += 4)
        out.insert(out.end(), {rgba[i + 2], rgba[i + 1], rgba[i], rgba[i + 3]});
    return out;
}

}  // namespace qvr::test
