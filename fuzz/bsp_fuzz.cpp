// libFuzzer target for the level loader: bytes starting with "PK" are opened as a pk3 and every
// maps/*.bsp inside is parsed with the archive's own textures and shader scripts; anything
// else is parsed as a BSP. Every input must give a scene that validates, or an error.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

#include "qvr/scene/bsp_loader.h"
#include "qvr/scene/pk3.h"
#include "qvr/scene/scene_loader.h"

namespace {

qvr::SceneLoadOptions fuzzOptions() {
    qvr::SceneLoadOptions o;
    o.patch_level = 3;
    o.max_texture_px = 64;
    // Small enough that a hostile patch count fails fast instead of exhausting memory.
    o.max_triangles = 1'000'000;
    return o;
}

void check(const qvr::Expected<qvr::Scene>& scene) {
    if (!scene.ok()) {
        if (scene.error().empty())
            std::abort();  // errors must say something
        return;
    }
    const qvr::Status s = qvr::validateScene(*scene);
    if (!s.ok()) {
        std::fprintf(stderr, "invalid scene from the loader: %s\n", s.error().c_str());
        std::abort();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    if (size >= 2 && data[0] == 'P' && data[1] == 'K') {
        auto archive =
            qvr::Pk3Archive::fromBytes(std::vector<uint8_t>(data, data + size), "fuzz.pk3");
        if (!archive.ok())
            return 0;
        std::vector<std::vector<uint8_t>> levels;
        for (size_t i = 0; i < (*archive)->names().size() && levels.size() < 4; ++i) {
            const std::string key = qvr::normalizeGamePath((*archive)->names()[i]);
            if (key.size() > 4 && key.compare(key.size() - 4, 4, ".bsp") == 0) {
                auto level = (*archive)->read(i);
                if (level.ok())
                    levels.push_back(std::move(*level));
            }
        }
        qvr::GameFileSystem files;
        files.addArchive(std::move(*archive));
        for (const auto& level : levels)
            check(qvr::parseBsp(level, "fuzz", &files, fuzzOptions()));
        return 0;
    }
    check(qvr::parseBsp(bytes, "fuzz", nullptr, fuzzOptions()));
    return 0;
}
