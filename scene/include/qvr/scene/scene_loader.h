// One entry point for every scene qvr renders: Quake III levels by name out of the Debian
// OpenArena/Nexuiz installations, files (.bsp, .pk3, .gltf/.glb/.obj), and built-in scenes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/scene/scene.h"

namespace qvr {

struct SceneLoadOptions {
    // Quads per side of each 3×3 Bézier sub-patch (Quake III face type 2): each sub-patch
    // becomes 2·level² triangles. 1…64.
    int patch_level = 8;
    bool load_textures = true;
    bool load_lightmaps = true;
    // Quake III levels: place the item entities' models (weapons, ammunition, health, armour,
    // powerups, flags; frame 0, unrotated, at the entity's origin) as interactive batches.
    // Off by default: the game draws items itself; a workload recording turns it on.
    bool load_items = false;
    // Textures larger than this are halved until they fit (0 = keep full size).
    int max_texture_px = 1024;
    // Lightmap brightening: each RGB byte is shifted left by this many bits and rescaled
    // hue-preservingly to stay ≤ 255, as Quake III's R_ColorShiftLightingBytes does with
    // r_mapOverBrightBits 2 and no hardware gamma. Applied to BSP vertex colours too.
    int lightmap_overbright_bits = 2;
    // Refuse to produce more triangles than this (guards against hostile patch counts).
    uint64_t max_triangles = 50'000'000;
    std::string openarena_dir = "/usr/share/games/openarena/baseoa";
    std::string nexuiz_dir = "/usr/share/games/nexuiz/data";
    // Objects in builtin:room unless the name says builtin:room?objects=N.
    int builtin_objects = 32;
};

// What a parse skipped, for `qvr scene info` and tests.
struct BspStats {
    int faces = 0;
    int items_placed = 0;         // item entities drawn (load_items)
    int items_without_model = 0;  // item entities whose model the game files lack
    int faces_drawn = 0;
    int faces_sky_or_nodraw = 0;  // SURF_SKY / SURF_NODRAW / SURF_SKIP / SURF_HINT shaders
    int faces_bad_shader = 0;     // shader index outside the texture lump
    int faces_flare_or_unknown = 0;
    int faces_empty = 0;
    int shaders_without_image = 0;            // drawn with vertex colour instead
    std::vector<std::string> missing_images;  // their shader names
};

// What a load did besides the scene, for `qvr scene info` and tests.
struct SceneLoadReport {
    std::string format;  // "ibsp46", "assimp", "builtin"
    BspStats bsp;        // Quake III levels only
};

// Names: "openarena:MAP", "nexuiz:MAP", "builtin:room[?objects=N]", or a path to a .bsp, a .pk3
// holding one level, or a .gltf/.glb/.obj file. Errors name what was missing and what exists.
Expected<Scene> loadScene(const std::string& name, const SceneLoadOptions& opts = {},
                          SceneLoadReport* report = nullptr);

// Triangles by origin: Quake III face types 1 and 3 (and every non-BSP triangle) versus
// tessellated Bézier patches (type 2), from the batches' is_patch flags.
struct SceneTriangleCounts {
    uint64_t triangles = 0;
    uint64_t patch_triangles = 0;
    uint64_t total() const { return triangles + patch_triangles; }
};
SceneTriangleCounts countSceneTriangles(const Scene& scene);

// Structural checks every loader's output must pass: indices within the vertex buffer, batches
// within the index buffer and whole triangles, texture/lightmap indices valid, texture sizes
// consistent, finite positions. Used by tests and after every load.
Status validateScene(const Scene& scene);

}  // namespace qvr
