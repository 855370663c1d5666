// A renderable scene: one vertex and index buffer, draw batches that each use one texture and
// one lightmap, the textures themselves, and where a player may stand. Every loader (Quake III
// BSP, Assimp, the built-in procedural scene) produces this; the renderer and the triangle
// counter consume it. Units are metres, OpenGL axes (y up, −z forward).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace qvr {

struct Aabb {
    glm::vec3 min{1e30f};
    glm::vec3 max{-1e30f};
    void extend(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    bool valid() const { return min.x <= max.x && min.y <= max.y && min.z <= max.z; }
};

struct SceneVertex {
    glm::vec3 position{0.0f};  // metres
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec2 uv{0.0f};           // texture coordinates
    glm::vec2 lightmap_uv{0.0f};  // lightmap coordinates (0 when the batch has no lightmap)
    glm::u8vec4 color{255, 255, 255, 255};
};

// RGBA8, rows top to bottom.
struct SceneTexture {
    std::string name;
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgba;
};

// One draw call: indices [first_index, first_index + index_count) of Scene::indices, triangles.
struct SceneBatch {
    uint32_t first_index = 0;
    uint32_t index_count = 0;
    int texture = -1;   // into Scene::textures, −1 = untextured (vertex colour)
    int lightmap = -1;  // into Scene::lightmaps, −1 = fully lit
    Aabb bounds;
    bool is_patch = false;  // tessellated Bézier patch (Quake III face type 2)
    // An object a player interacts with (a game item, a chess piece): the static collaborative
    // design's foreground (paper §2, Table 1); the rest of the scene is its background.
    bool interactive = false;
};

struct SpawnPoint {
    glm::vec3 position_m{0.0f};  // eye position
    float yaw_deg = 0.0f;        // about +y, 0 = looking down −z
};

struct Scene {
    std::string name;  // "openarena:oa_dm5", "builtin:room", a path
    std::vector<SceneVertex> vertices;
    std::vector<uint32_t> indices;
    std::vector<SceneBatch> batches;
    std::vector<SceneTexture> textures;
    std::vector<SceneTexture> lightmaps;
    std::vector<SpawnPoint> spawns;
    Aabb bounds;

    size_t triangleCount() const { return indices.size() / 3; }
};

}  // namespace qvr
