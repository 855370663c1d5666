// Quake III Arena BSP (IBSP version 46) to qvr::Scene: polygon, mesh and tessellated Bézier
// patch faces, textures found through the game file system, lightmaps and spawn points. The
// bytes are untrusted: every lump, offset, count and index is checked before use.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/scene/pk3.h"
#include "qvr/scene/scene.h"
#include "qvr/scene/scene_loader.h"

namespace qvr {

// Quake units to metres: one unit is one inch.
inline constexpr float kQuakeUnitM = 0.0254f;
// Eye above a spawn entity's origin: the game spawns the player 9 units up and puts the view
// 26 units (DEFAULT_VIEWHEIGHT) above the player origin.
inline constexpr float kQuakeSpawnEyeUnits = 9.0f + 26.0f;
// Bézier patch control grids larger than this per side are rejected (q3map's MAX_PATCH_SIZE is 32).
inline constexpr int kMaxPatchSide = 65;

// Parses a BSP held in memory. files supplies textures and shader scripts (may be null: no
// textures). The returned scene is named scene_name.
Expected<Scene> parseBsp(std::span<const uint8_t> bytes, const std::string& scene_name,
                         const GameFileSystem* files, const SceneLoadOptions& opts,
                         BspStats* stats = nullptr);

// Quake III (x east, y north, z up, inches) to qvr (x right, y up, −z forward, metres).
inline glm::vec3 quakeToScene(const glm::vec3& q) {
    return glm::vec3(q.x, q.z, -q.y) * kQuakeUnitM;
}

}  // namespace qvr
