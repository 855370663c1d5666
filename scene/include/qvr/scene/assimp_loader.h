// glTF 2.0 (.gltf/.glb), Wavefront OBJ and the other formats Assimp reads, as one qvr::Scene:
// triangulated, with generated smooth normals where the file has none, UVs with v = 0 at the
// top row of the image, textures from files next to the model or embedded in it, otherwise the
// material's diffuse colour as vertex colour. Units are taken as metres, y up.
#pragma once

#include <string>

#include "qvr/core/expected.h"
#include "qvr/scene/scene.h"
#include "qvr/scene/scene_loader.h"

namespace qvr {

Expected<Scene> loadAssimpScene(const std::string& path, const SceneLoadOptions& opts);

}  // namespace qvr
