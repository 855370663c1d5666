// Small scenes built by hand for the render tests: textured walls of a room, a lightmapped
// floor and single coloured quads placed where a test wants them.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include <glm/geometric.hpp>

#include "qvr/scene/scene.h"

namespace qvr::test {

// Appends the quad p0 p1 p2 p3 (in order around it) as one batch of two triangles.
inline int addQuad(Scene& scene, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                   const glm::vec3& p3, int texture, int lightmap, glm::u8vec4 color,
                   float uv_repeat = 1.0f) {
    const auto base = static_cast<uint32_t>(scene.vertices.size());
    const glm::vec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    const glm::vec3 corners[4] = {p0, p1, p2, p3};
    const glm::vec2 uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    SceneBatch batch;
    batch.first_index = static_cast<uint32_t>(scene.indices.size());
    batch.index_count = 6;
    batch.texture = texture;
    batch.lightmap = lightmap;
    for (int i = 0; i < 4; ++i) {
        SceneVertex v;
        v.position = corners[i];
        v.normal = n;
        v.uv = uvs[i] * uv_repeat;
        v.lightmap_uv = uvs[i];
        v.color = color;
        scene.vertices.push_back(v);
        batch.bounds.extend(corners[i]);
        scene.bounds.extend(corners[i]);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
        scene.indices.push_back(base + i);
    scene.batches.push_back(batch);
    return static_cast<int>(scene.batches.size()) - 1;
}

// A detailed texture: a checkerboard with a hashed per-texel variation, so that down-sampling
// has real high frequencies to remove.
inline SceneTexture detailTexture(const std::string& name, int size, glm::u8vec4 a, glm::u8vec4 b) {
    SceneTexture t;
    t.name = name;
    t.width = size;
    t.height = size;
    t.rgba.resize(static_cast<size_t>(size) * size * 4);
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            const bool odd = ((x / 8) + (y / 8)) % 2 != 0;
            const glm::u8vec4 c = odd ? a : b;
            const uint32_t h =
                (static_cast<uint32_t>(x) * 73856093u) ^ (static_cast<uint32_t>(y) * 19349663u);
            const int jitter = static_cast<int>(h % 41u) - 20;
            uint8_t* p = &t.rgba[(static_cast<size_t>(y) * size + x) * 4];
            for (int k = 0; k < 3; ++k)
                p[k] = static_cast<uint8_t>(std::clamp(static_cast<int>(c[k]) + jitter, 0, 255));
            p[3] = 255;
        }
    }
    return t;
}

// A lightmap that brightens from one edge to the other.
inline SceneTexture gradientLightmap(int size) {
    SceneTexture t;
    t.name = "lightmap";
    t.width = size;
    t.height = size;
    t.rgba.resize(static_cast<size_t>(size) * size * 4);
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            uint8_t* p = &t.rgba[(static_cast<size_t>(y) * size + x) * 4];
            const auto v = static_cast<uint8_t>(96 + (159 * x) / std::max(1, size - 1));
            p[0] = p[1] = p[2] = v;
            p[3] = 255;
        }
    }
    return t;
}

// A 4 m wide, 3 m high, 8 m deep room around the origin (eye height 0, floor at −1.5 m), each
// wall its own textured batch, the floor lightmapped, and a vertex-coloured box in front.
inline Scene texturedRoom() {
    Scene s;
    s.name = "test:room";
    s.textures.push_back(detailTexture("wall_a", 128, {200, 60, 50, 255}, {230, 210, 180, 255}));
    s.textures.push_back(detailTexture("wall_b", 128, {40, 90, 200, 255}, {220, 220, 220, 255}));
    s.textures.push_back(detailTexture("floor", 256, {60, 160, 70, 255}, {30, 40, 30, 255}));
    s.lightmaps.push_back(gradientLightmap(16));
    const float x0 = -2, x1 = 2, y0 = -1.5f, y1 = 1.5f, z0 = -6, z1 = 2;
    const glm::u8vec4 white{255, 255, 255, 255};
    addQuad(s, {x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0}, 0, -1, white, 3);  // back
    addQuad(s, {x0, y0, z1}, {x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, 1, -1, white, 4);  // left
    addQuad(s, {x1, y0, z0}, {x1, y0, z1}, {x1, y1, z1}, {x1, y1, z0}, 1, -1, white, 4);  // right
    addQuad(s, {x0, y0, z1}, {x1, y0, z1}, {x1, y0, z0}, {x0, y0, z0}, 2, 0, white, 6);   // floor
    addQuad(s, {x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1}, 0, -1, white, 4);  // ceiling
    addQuad(s, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}, 1, -1, white, 3);  // behind
    // A box standing on the floor, untextured, its faces in distinct vertex colours.
    const float bx0 = -0.5f, bx1 = 0.3f, by0 = -1.5f, by1 = -0.7f, bz0 = -3.5f, bz1 = -2.7f;
    addQuad(s, {bx0, by0, bz1}, {bx1, by0, bz1}, {bx1, by1, bz1}, {bx0, by1, bz1}, -1, -1,
            {250, 200, 40, 255});
    addQuad(s, {bx0, by1, bz1}, {bx1, by1, bz1}, {bx1, by1, bz0}, {bx0, by1, bz0}, -1, -1,
            {40, 220, 220, 255});
    addQuad(s, {bx1, by0, bz1}, {bx1, by0, bz0}, {bx1, by1, bz0}, {bx1, by1, bz1}, -1, -1,
            {200, 40, 200, 255});
    s.spawns.push_back({{0.0f, 0.0f, 0.0f}, 0.0f});
    return s;
}

}  // namespace qvr::test
