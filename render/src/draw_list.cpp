// Spatial clusters for CPU frustum culling: triangles of a batch sorted by the Morton code of
// their centroids (30 bits over the batch's box) and cut into runs of equal size.
#include "qvr/render/draw_list.h"

#include <algorithm>
#include <numeric>

#include <fmt/format.h>

#include <glm/common.hpp>

namespace qvr {

namespace {

// Spreads the low 10 bits of v so that two zero bits separate each.
uint32_t spreadBits(uint32_t v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

uint32_t mortonCode(const glm::vec3& unit) {
    const glm::vec3 q = glm::clamp(unit * 1023.0f, glm::vec3(0.0f), glm::vec3(1023.0f));
    return (spreadBits(static_cast<uint32_t>(q.x)) << 2) |
           (spreadBits(static_cast<uint32_t>(q.y)) << 1) | spreadBits(static_cast<uint32_t>(q.z));
}

}  // namespace

Status checkDrawable(const Scene& scene) {
    for (const SceneBatch& b : scene.batches) {
        const uint64_t end = static_cast<uint64_t>(b.first_index) + b.index_count;
        if (end > scene.indices.size() || b.index_count % 3 != 0)
            return makeError(
                fmt::format("render: scene '{}' has a batch of indices [{}, {}) of {} indices",
                            scene.name, b.first_index, end, scene.indices.size()));
        if (b.texture < -1 || b.texture >= static_cast<int>(scene.textures.size()) ||
            b.lightmap < -1 || b.lightmap >= static_cast<int>(scene.lightmaps.size()))
            return makeError(fmt::format(
                "render: scene '{}' has a batch with texture {} of {} and lightmap {} of {}",
                scene.name, b.texture, scene.textures.size(), b.lightmap, scene.lightmaps.size()));
    }
    for (uint32_t i : scene.indices) {
        if (i >= scene.vertices.size())
            return makeError(fmt::format("render: scene '{}' has vertex index {} of {}", scene.name,
                                         i, scene.vertices.size()));
    }
    for (const auto* set : {&scene.textures, &scene.lightmaps}) {
        for (const SceneTexture& t : *set) {
            const size_t bytes = static_cast<size_t>(std::max(t.width, 0)) *
                                 static_cast<size_t>(std::max(t.height, 0)) * 4;
            if (t.width <= 0 || t.height <= 0 || t.rgba.size() != bytes)
                return makeError(
                    fmt::format("render: scene '{}': texture '{}' is {}x{} with {} "
                                "bytes of RGBA8",
                                scene.name, t.name, t.width, t.height, t.rgba.size()));
        }
    }
    return Status::success();
}

DrawList buildDrawList(const Scene& scene, uint32_t cluster_triangles) {
    DrawList list;
    list.indices = scene.indices;
    cluster_triangles = std::max<uint32_t>(1, cluster_triangles);
    std::vector<uint32_t> order;
    std::vector<uint32_t> codes;
    std::vector<uint32_t> scratch;
    for (size_t b = 0; b < scene.batches.size(); ++b) {
        const SceneBatch& batch = scene.batches[b];
        const uint32_t tris = batch.index_count / 3;
        if (tris == 0)
            continue;
        const uint32_t* src = scene.indices.data() + batch.first_index;
        if (tris > cluster_triangles) {
            Aabb whole;
            for (uint32_t i = 0; i < 3 * tris; ++i)
                whole.extend(scene.vertices[src[i]].position);
            const glm::vec3 extent = glm::max(whole.max - whole.min, glm::vec3(1e-6f));
            codes.resize(tris);
            for (uint32_t t = 0; t < tris; ++t) {
                const glm::vec3 c =
                    (scene.vertices[src[3 * t]].position + scene.vertices[src[3 * t + 1]].position +
                     scene.vertices[src[3 * t + 2]].position) /
                    3.0f;
                codes[t] = mortonCode((c - whole.min) / extent);
            }
            order.resize(tris);
            std::iota(order.begin(), order.end(), 0u);
            std::stable_sort(order.begin(), order.end(),
                             [&](uint32_t a, uint32_t c) { return codes[a] < codes[c]; });
            scratch.resize(3 * static_cast<size_t>(tris));
            for (uint32_t t = 0; t < tris; ++t) {
                for (int k = 0; k < 3; ++k)
                    scratch[3 * static_cast<size_t>(t) + k] = src[3 * order[t] + k];
            }
            std::copy(scratch.begin(), scratch.end(),
                      list.indices.begin() + static_cast<std::ptrdiff_t>(batch.first_index));
        }
        const uint32_t* dst = list.indices.data() + batch.first_index;
        for (uint32_t t0 = 0; t0 < tris; t0 += cluster_triangles) {
            const uint32_t n = std::min(cluster_triangles, tris - t0);
            DrawCluster c;
            c.first_index = batch.first_index + 3 * t0;
            c.index_count = 3 * n;
            c.batch = static_cast<uint32_t>(b);
            for (uint32_t i = 0; i < 3 * n; ++i)
                c.bounds.extend(scene.vertices[dst[3 * t0 + i]].position);
            list.clusters.push_back(c);
        }
    }
    return list;
}

DrawSelection selectDraws(const DrawList& list, const RenderView& view) {
    DrawSelection s;
    const FrustumPlanes planes = frustumPlanes(view.viewProjection());
    for (const DrawCluster& c : list.clusters) {
        if (!boxMayBeVisible(planes, c.bounds)) {
            ++s.clusters_culled;
            continue;
        }
        ++s.clusters_drawn;
        s.triangles += c.index_count / 3;
        // Clusters of one batch are adjacent in the index buffer: extend the last draw.
        if (!s.draws.empty() && s.draws.back().batch == c.batch &&
            s.draws.back().first_index + s.draws.back().index_count == c.first_index) {
            s.draws.back().index_count += c.index_count;
        } else {
            s.draws.push_back({c.first_index, c.index_count, c.batch});
        }
    }
    return s;
}

}  // namespace qvr
