// Assimp import: every mesh of the file, pre-transformed into one vertex buffer, one batch per
// (mesh, material). glTF is metres and y-up by specification; OBJ has no units and is taken as
// the same.
#include "qvr/scene/assimp_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "image_decode.h"

namespace qvr {

namespace {

// Loads the material's diffuse (or glTF base colour) texture; −1 when it has none or it cannot
// be read.
int materialTexture(const aiScene* ai, const aiMaterial* mat, const std::filesystem::path& dir,
                    const SceneLoadOptions& opts, Scene& scene, std::map<std::string, int>& cache) {
    aiString path;
    if (mat->GetTexture(aiTextureType_BASE_COLOR, 0, &path) != AI_SUCCESS &&
        mat->GetTexture(aiTextureType_DIFFUSE, 0, &path) != AI_SUCCESS)
        return -1;
    const std::string key = path.C_Str();
    if (const auto it = cache.find(key); it != cache.end())
        return it->second;
    int index = -1;
    Expected<SceneTexture> tex = makeError("not found");
    if (const aiTexture* embedded = ai->GetEmbeddedTexture(path.C_Str())) {
        if (embedded->mHeight == 0) {
            // Compressed (PNG/JPEG) bytes; mWidth is their length.
            tex = decodeImage(
                std::span(reinterpret_cast<const uint8_t*>(embedded->pcData), embedded->mWidth),
                key, opts.max_texture_px);
        } else if (embedded->mWidth <= kMaxDecodedImageSide &&
                   embedded->mHeight <= kMaxDecodedImageSide) {
            SceneTexture t;
            t.name = key;
            t.width = static_cast<int>(embedded->mWidth);
            t.height = static_cast<int>(embedded->mHeight);
            const size_t n = static_cast<size_t>(t.width) * static_cast<size_t>(t.height);
            t.rgba.resize(n * 4);
            for (size_t i = 0; i < n; ++i) {
                const aiTexel& x = embedded->pcData[i];
                t.rgba[4 * i] = x.r;
                t.rgba[4 * i + 1] = x.g;
                t.rgba[4 * i + 2] = x.b;
                t.rgba[4 * i + 3] = x.a;
            }
            tex = std::move(t);
        }
    } else {
        std::string rel = key;
        std::replace(rel.begin(), rel.end(), '\\', '/');
        std::ifstream in(dir / rel, std::ios::binary);
        if (in) {
            std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                       std::istreambuf_iterator<char>());
            tex = decodeImage(bytes, key, opts.max_texture_px);
        }
    }
    if (tex) {
        index = static_cast<int>(scene.textures.size());
        scene.textures.push_back(std::move(*tex));
    }
    cache[key] = index;
    return index;
}

glm::u8vec4 materialColor(const aiMaterial* mat) {
    aiColor4D c(1, 1, 1, 1);
    if (mat->Get(AI_MATKEY_BASE_COLOR, c) != AI_SUCCESS)
        mat->Get(AI_MATKEY_COLOR_DIFFUSE, c);
    auto to8 = [](float x) {
        return static_cast<uint8_t>(std::clamp(x, 0.0f, 1.0f) * 255.0f + 0.5f);
    };
    return glm::u8vec4(to8(c.r), to8(c.g), to8(c.b), to8(c.a));
}

}  // namespace

Expected<Scene> loadAssimpScene(const std::string& path, const SceneLoadOptions& opts) {
    Assimp::Importer importer;
    // Points and lines are not drawn; removing them lets SortByPType leave only triangles.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_GenSmoothNormals |
                           aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                           aiProcess_SortByPType | aiProcess_FlipUVs |
                           aiProcess_ValidateDataStructure;
    const aiScene* ai = importer.ReadFile(path, flags);
    if (ai == nullptr || (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || ai->mRootNode == nullptr)
        return makeError(
            fmt::format("{}: Assimp cannot import it: {}", path, importer.GetErrorString()));
    Scene scene;
    scene.name = path;
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    std::map<std::string, int> cache;
    uint64_t triangles = 0;
    for (unsigned mi = 0; mi < ai->mNumMeshes; ++mi) {
        const aiMesh* mesh = ai->mMeshes[mi];
        if ((mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 || mesh->mNumFaces == 0)
            continue;
        const aiMaterial* mat = mesh->mMaterialIndex < ai->mNumMaterials
                                    ? ai->mMaterials[mesh->mMaterialIndex]
                                    : nullptr;
        const int texture = (mat != nullptr && opts.load_textures && mesh->HasTextureCoords(0))
                                ? materialTexture(ai, mat, dir, opts, scene, cache)
                                : -1;
        const glm::u8vec4 base_color = mat != nullptr ? materialColor(mat) : glm::u8vec4(255);
        const uint64_t base64 = scene.vertices.size();
        if (base64 + mesh->mNumVertices > UINT32_MAX)
            return makeError(fmt::format("{}: more than 2^32 vertices", path));
        const uint32_t base = static_cast<uint32_t>(base64);
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            SceneVertex sv;
            const aiVector3D& p = mesh->mVertices[v];
            sv.position = glm::vec3(p.x, p.y, p.z);
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                return makeError(fmt::format("{}: mesh {} vertex {} is not finite", path, mi, v));
            if (mesh->HasNormals()) {
                const aiVector3D& n = mesh->mNormals[v];
                const glm::vec3 gn(n.x, n.y, n.z);
                const float len = glm::length(gn);
                sv.normal = std::isfinite(len) && len > 1e-6f ? gn / len : glm::vec3(0, 1, 0);
            }
            if (mesh->HasTextureCoords(0))
                sv.uv = glm::vec2(mesh->mTextureCoords[0][v].x, mesh->mTextureCoords[0][v].y);
            if (mesh->HasVertexColors(0)) {
                const aiColor4D& c = mesh->mColors[0][v];
                auto to8 = [](float x) {
                    return static_cast<uint8_t>(std::clamp(x, 0.0f, 1.0f) * 255.0f + 0.5f);
                };
                sv.color = glm::u8vec4(to8(c.r), to8(c.g), to8(c.b), to8(c.a));
            } else {
                // A textured material's colour factor would tint; untextured shows its colour.
                sv.color = texture >= 0 ? glm::u8vec4(255) : base_color;
            }
            scene.vertices.push_back(sv);
        }
        SceneBatch b;
        b.first_index = static_cast<uint32_t>(scene.indices.size());
        b.texture = texture;
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3)
                continue;
            for (unsigned k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= mesh->mNumVertices)
                    return makeError(
                        fmt::format("{}: mesh {} face {} index past its vertices", path, mi, f));
                scene.indices.push_back(base + face.mIndices[k]);
                b.bounds.extend(scene.vertices[base + face.mIndices[k]].position);
            }
            if (++triangles > opts.max_triangles)
                return makeError(
                    fmt::format("{}: more than {} triangles", path, opts.max_triangles));
        }
        b.index_count = static_cast<uint32_t>(scene.indices.size()) - b.first_index;
        if (b.index_count == 0)
            continue;
        scene.bounds.extend(b.bounds.min);
        scene.bounds.extend(b.bounds.max);
        scene.batches.push_back(b);
    }
    if (scene.batches.empty())
        return makeError(fmt::format("{}: no triangles", path));
    // A file has no player start; stand 1.7 m above the floor of the bounds, back from the
    // centre along +z by the scene's depth, looking down −z.
    const glm::vec3 c = 0.5f * (scene.bounds.min + scene.bounds.max);
    const glm::vec3 ext = scene.bounds.max - scene.bounds.min;
    scene.spawns.push_back({glm::vec3(c.x, scene.bounds.min.y + std::min(1.7f, ext.y + 1.7f),
                                      scene.bounds.max.z + 0.5f * std::max(ext.x, ext.y)),
                            0.0f});
    return scene;
}

}  // namespace qvr
