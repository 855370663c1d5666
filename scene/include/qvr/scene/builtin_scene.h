// Built-in procedural scenes, so the default run needs no downloads: "room" is a furnished room
// with a board of lathe-turned chess-like pieces, spheres and tori (in the spirit of the chess
// scene of Guenter et al.'s Foveated 3D Graphics), with procedural textures that give the
// video codec real detail.
#pragma once

#include <string>

#include "qvr/core/expected.h"
#include "qvr/scene/scene.h"

namespace qvr {

inline constexpr int kMaxBuiltinObjects = 4096;

// objects: 0…kMaxBuiltinObjects detailed objects (about 4–8 k triangles each).
Scene makeBuiltinRoom(int objects);

// "room" or "room?objects=N"; default_objects when the query is absent.
Expected<Scene> makeBuiltinScene(const std::string& spec, int default_objects);

}  // namespace qvr
