// Scene-name resolution: installations of Quake III-format games, files, and built-ins.
#include "qvr/scene/scene_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "qvr/scene/assimp_loader.h"
#include "qvr/scene/bsp_loader.h"
#include "qvr/scene/builtin_scene.h"

namespace qvr {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// "maps/oa_dm5.bsp" → "oa_dm5".
std::string mapNameOf(const std::string& game_path) {
    std::string n = game_path.substr(game_path.find('/') + 1);
    return n.substr(0, n.size() - 4);
}

// Up to a dozen map names, those sharing the longest prefix with `wanted` first.
std::string someMaps(std::vector<std::string> bsps, const std::string& wanted = "") {
    auto common = [&](const std::string& path) {
        const std::string n = mapNameOf(path);
        size_t k = 0;
        while (k < n.size() && k < wanted.size() && n[k] == wanted[k])
            ++k;
        return k;
    };
    std::stable_sort(bsps.begin(), bsps.end(), [&](const std::string& a, const std::string& b) {
        return common(a) > common(b);
    });
    std::string out;
    const size_t shown = std::min<size_t>(bsps.size(), 12);
    for (size_t i = 0; i < shown; ++i)
        out += (i ? ", " : "") + mapNameOf(bsps[i]);
    if (bsps.size() > shown)
        out += fmt::format(", … ({} in all)", bsps.size());
    return out;
}

Expected<Scene> finish(Expected<Scene> scene) {
    if (!scene)
        return scene;
    if (Status s = validateScene(*scene); !s)
        return makeError(
            fmt::format("{}: loader produced an inconsistent scene: {}", scene->name, s.error()));
    return scene;
}

Expected<Scene> loadInstalledMap(const std::string& game, const std::string& dir,
                                 const std::string& package_hint, const std::string& map,
                                 const SceneLoadOptions& opts, BspStats* stats) {
    const std::string name = game + ":" + map;
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
        return makeError(
            fmt::format("{}: {} is not installed ({} not found; install the Debian "
                        "packages {})",
                        name, game, dir, package_hint));
    GameFileSystem files;
    if (Status s = files.addPk3Directory(dir); !s)
        return makeError(fmt::format("{}: {}", name, s.error()));
    if (map.empty() || map.find('/') != std::string::npos)
        return makeError(fmt::format(
            "{}: give a map name, e.g. {}:{}", name, game,
            mapNameOf(files.list("maps/", ".bsp").empty() ? std::string("maps/x.bsp")
                                                          : files.list("maps/", ".bsp").front())));
    const std::string path = "maps/" + map + ".bsp";
    auto bytes = files.read(path);
    if (!bytes) {
        const auto bsps = files.list("maps/", ".bsp");
        return makeError(fmt::format("{}: no {} in the {} pk3 files of {}; available: {}", name,
                                     path, files.archiveCount(), dir, someMaps(bsps, lower(map))));
    }
    return finish(parseBsp(*bytes, name, &files, opts, stats));
}

Expected<std::vector<uint8_t>> readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return makeError(fmt::format("{}: cannot open", path));
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0 || static_cast<uint64_t>(size) > kMaxArchiveMemberBytes)
        return makeError(
            fmt::format("{}: unreadable or larger than {} MB", path, kMaxArchiveMemberBytes >> 20));
    in.seekg(0);
    std::vector<uint8_t> out(static_cast<size_t>(size));
    in.read(reinterpret_cast<char*>(out.data()), size);
    if (!in)
        return makeError(fmt::format("{}: read error", path));
    return out;
}

// Textures for a level given as a file: the OpenArena installation when present (most
// community levels use its textures), then loose files of the level's own game directory.
void addTextureSources(GameFileSystem& files, const std::string& bsp_path,
                       const SceneLoadOptions& opts) {
    std::error_code ec;
    if (std::filesystem::is_directory(opts.openarena_dir, ec))
        (void)files.addPk3Directory(opts.openarena_dir);
    const std::filesystem::path p(bsp_path);
    std::filesystem::path dir = p.parent_path();
    if (lower(dir.filename().string()) == "maps")
        dir = dir.parent_path();
    files.addLooseDirectory(dir.empty() ? "." : dir.string());
}

Expected<Scene> loadBspFile(const std::string& path, const SceneLoadOptions& opts,
                            BspStats* stats) {
    auto bytes = readFile(path);
    if (!bytes)
        return makeError(bytes.error());
    GameFileSystem files;
    addTextureSources(files, path, opts);
    return finish(parseBsp(*bytes, path, &files, opts, stats));
}

Expected<Scene> loadPk3File(const std::string& path, const SceneLoadOptions& opts,
                            BspStats* stats) {
    auto archive = Pk3Archive::open(path);
    if (!archive)
        return makeError(archive.error());
    std::vector<std::string> bsps;
    for (const auto& n : (*archive)->names()) {
        const std::string key = normalizeGamePath(n);
        if (key.rfind("maps/", 0) == 0 && endsWith(key, ".bsp"))
            bsps.push_back(key);
    }
    if (bsps.size() != 1)
        return makeError(
            fmt::format("{}: holds {} levels (maps/*.bsp){}; a pk3 scene must hold "
                        "exactly one",
                        path, bsps.size(), bsps.empty() ? std::string() : ": " + someMaps(bsps)));
    auto bytes = (*archive)->read(bsps.front());
    if (!bytes)
        return makeError(bytes.error());
    GameFileSystem files;
    std::error_code ec;
    if (std::filesystem::is_directory(opts.openarena_dir, ec))
        (void)files.addPk3Directory(opts.openarena_dir);
    files.addArchive(std::move(*archive));  // the level's own files win
    return finish(parseBsp(*bytes, path, &files, opts, stats));
}

}  // namespace

Expected<Scene> loadScene(const std::string& name, const SceneLoadOptions& opts,
                          SceneLoadReport* report) {
    SceneLoadReport local;
    SceneLoadReport& r = report != nullptr ? *report : local;
    r = SceneLoadReport{};
    if (name.rfind("openarena:", 0) == 0) {
        r.format = "ibsp46";
        return loadInstalledMap("openarena", opts.openarena_dir,
                                "openarena-081-maps openarena-081-textures openarena-data",
                                name.substr(10), opts, &r.bsp);
    }
    if (name.rfind("nexuiz:", 0) == 0) {
        r.format = "ibsp46";
        return loadInstalledMap("nexuiz", opts.nexuiz_dir, "nexuiz-data", name.substr(7), opts,
                                &r.bsp);
    }
    if (name.rfind("builtin:", 0) == 0) {
        r.format = "builtin";
        return finish(makeBuiltinScene(name.substr(8), opts.builtin_objects));
    }
    std::error_code ec;
    if (!std::filesystem::is_regular_file(name, ec))
        return makeError(
            fmt::format("{}: no such file; a scene is openarena:MAP, nexuiz:MAP, "
                        "builtin:room[?objects=N] or a .bsp/.pk3/.gltf/.glb/.obj file",
                        name));
    const std::string ext = lower(std::filesystem::path(name).extension().string());
    if (ext == ".bsp" || ext == ".pk3") {
        r.format = "ibsp46";
        return ext == ".bsp" ? loadBspFile(name, opts, &r.bsp) : loadPk3File(name, opts, &r.bsp);
    }
    r.format = "assimp";
    return finish(loadAssimpScene(name, opts));
}

SceneTriangleCounts countSceneTriangles(const Scene& scene) {
    SceneTriangleCounts c;
    for (const auto& b : scene.batches)
        (b.is_patch ? c.patch_triangles : c.triangles) += b.index_count / 3;
    return c;
}

Status validateScene(const Scene& scene) {
    if (scene.indices.size() % 3 != 0)
        return makeError(fmt::format("{} indices is not whole triangles", scene.indices.size()));
    for (size_t i = 0; i < scene.indices.size(); ++i) {
        if (scene.indices[i] >= scene.vertices.size())
            return makeError(fmt::format("index {} = {} past {} vertices", i, scene.indices[i],
                                         scene.vertices.size()));
    }
    for (size_t i = 0; i < scene.vertices.size(); ++i) {
        const glm::vec3& p = scene.vertices[i].position;
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return makeError(fmt::format("vertex {} is not finite", i));
    }
    uint64_t covered = 0;
    for (size_t i = 0; i < scene.batches.size(); ++i) {
        const SceneBatch& b = scene.batches[i];
        if (b.index_count % 3 != 0 ||
            static_cast<uint64_t>(b.first_index) + b.index_count > scene.indices.size())
            return makeError(
                fmt::format("batch {} [{}, +{}) is not whole triangles within {} "
                            "indices",
                            i, b.first_index, b.index_count, scene.indices.size()));
        if (b.texture < -1 || b.texture >= static_cast<int>(scene.textures.size()))
            return makeError(
                fmt::format("batch {}: texture {} of {}", i, b.texture, scene.textures.size()));
        if (b.lightmap < -1 || b.lightmap >= static_cast<int>(scene.lightmaps.size()))
            return makeError(
                fmt::format("batch {}: lightmap {} of {}", i, b.lightmap, scene.lightmaps.size()));
        covered += b.index_count;
    }
    if (covered != scene.indices.size())
        return makeError(
            fmt::format("batches cover {} of {} indices", covered, scene.indices.size()));
    for (const auto* list : {&scene.textures, &scene.lightmaps}) {
        for (const auto& t : *list) {
            if (t.width <= 0 || t.height <= 0 ||
                t.rgba.size() != static_cast<size_t>(t.width) * static_cast<size_t>(t.height) * 4)
                return makeError(fmt::format("texture {} is {}x{} with {} bytes", t.name, t.width,
                                             t.height, t.rgba.size()));
        }
    }
    return Status::success();
}

}  // namespace qvr
