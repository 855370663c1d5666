// Spatial clusters for CPU frustum culling: triangles of a batch sorted by the Morton code of
// their centroids (30 bits over the batch's box) and cut into runs of equal size.
#include "qvr/render/draw_list.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include <fmt/format.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

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

using Triangle = std::array<uint32_t, 3>;

struct TriangleHash {
    size_t operator()(const Triangle& t) const {
        uint64_t h = t[0] * 0x9E3779B97F4A7C15ull;
        h ^= (h >> 29) + t[1] * 0xBF58476D1CE4E5B9ull;
        h ^= (h >> 31) + t[2] * 0x94D049BB133111EBull;
        return static_cast<size_t>(h ^ (h >> 32));
    }
};

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

void buildLods(DrawList& list, const Scene& scene, const LodOptions& options) {
    // Drop any earlier levels: their indices are the tail after the scene's own.
    size_t base_indices = list.indices.size();
    for (const DrawLodLevel& l : list.lods)
        for (uint32_t n : l.index_count)
            base_indices -= n;
    list.indices.resize(base_indices);
    list.lods.clear();
    list.lod_vertices.clear();
    if (scene.vertices.empty() || list.clusters.empty() || options.levels <= 0)
        return;
    Aabb box = scene.bounds;
    if (!box.valid()) {
        box = Aabb{};
        for (const SceneVertex& v : scene.vertices)
            box.extend(v.position);
    }
    const float diagonal = glm::length(box.max - box.min);
    float cell = options.finest_cell_m > 0.0f ? options.finest_cell_m : diagonal / 4096.0f;
    if (!(cell > 0.0f))
        return;
    const uint32_t vertex_base = static_cast<uint32_t>(scene.vertices.size());
    std::unordered_map<uint64_t, uint32_t> cell_vertex;  // (batch, cell) → LOD vertex
    std::unordered_set<Triangle, TriangleHash> seen;     // triangles already in a cluster
    for (int level = 0; level < options.levels; ++level, cell *= 2.0f) {
        // Cells are counted from the box's corner with 20 bits an axis; past that, stop.
        if (diagonal / cell > float(1u << 20))
            continue;
        DrawLodLevel lod;
        lod.cell_m = cell;
        lod.first_index.reserve(list.clusters.size());
        lod.index_count.reserve(list.clusters.size());
        cell_vertex.clear();
        uint32_t batch_of_map = UINT32_MAX;
        for (const DrawCluster& c : list.clusters) {
            if (c.batch != batch_of_map) {
                // Vertices keep their batch's texture coordinates: one set per batch.
                cell_vertex.clear();
                batch_of_map = c.batch;
            }
            const uint32_t first = static_cast<uint32_t>(list.indices.size());
            seen.clear();
            auto mapped = [&](uint32_t vi) {
                const SceneVertex& v = scene.vertices[vi];
                const glm::vec3 q = glm::floor((v.position - box.min) / cell);
                const glm::uvec3 k =
                    glm::uvec3(glm::clamp(q, glm::vec3(0.0f), glm::vec3(1048575.0f)));
                const uint64_t key = (uint64_t(k.x) << 40) | (uint64_t(k.y) << 20) | uint64_t(k.z);
                auto [it, fresh] = cell_vertex.try_emplace(key, 0u);
                if (fresh) {
                    SceneVertex lv = v;
                    lv.position = box.min + (glm::vec3(k) + 0.5f) * cell;
                    it->second = vertex_base + static_cast<uint32_t>(list.lod_vertices.size());
                    list.lod_vertices.push_back(lv);
                }
                return it->second;
            };
            for (uint32_t i = 0; i < c.index_count; i += 3) {
                const uint32_t* t = list.indices.data() + c.first_index + i;
                const uint32_t a = mapped(t[0]), b = mapped(t[1]), d = mapped(t[2]);
                if (a == b || b == d || a == d)
                    continue;
                // The same triangle twice (same winding, any rotation) draws nothing new.
                const uint32_t lo = std::min({a, b, d});
                const uint32_t r0 = lo, r1 = lo == a ? b : (lo == b ? d : a),
                               r2 = lo == a ? d : (lo == b ? a : b);
                if (!seen.insert(Triangle{r0, r1, r2}).second)
                    continue;
                list.indices.push_back(a);
                list.indices.push_back(b);
                list.indices.push_back(d);
            }
            lod.first_index.push_back(first);
            lod.index_count.push_back(static_cast<uint32_t>(list.indices.size()) - first);
        }
        list.lods.push_back(std::move(lod));
    }
}

namespace {

// The coarsest level whose largest vertex move, seen from the eye at the box's nearest point,
// stays within lod_error_px pixels; -1 for full detail.
int lodLevelFor(const DrawList& list, const Aabb& bounds, const glm::vec3& eye, float px_per_rad,
                float lod_error_px) {
    const glm::vec3 nearest = glm::clamp(eye, bounds.min, bounds.max);
    const float d = glm::length(nearest - eye);
    // A vertex moves at most half a cell diagonal: √3/2 · cell.
    const float max_cell = lod_error_px * d / (0.8660254f * px_per_rad);
    int level = -1;
    while (level + 1 < static_cast<int>(list.lods.size()) &&
           list.lods[static_cast<size_t>(level + 1)].cell_m <= max_cell)
        ++level;
    return level;
}

float pixelsPerRadian(const RenderView& view) {
    // Pixels per unit of tangent: the projection's scale times half the framebuffer.
    return std::max(std::fabs(view.projection[0][0]) * 0.5f * float(view.width_px),
                    std::fabs(view.projection[1][1]) * 0.5f * float(view.height_px));
}

}  // namespace

void addTrianglesPerRing(const DrawList& list, const RenderView& view, float lod_error_px,
                         const glm::vec3& axis, double ring_deg, std::vector<double>& rings) {
    if (rings.empty() || !(ring_deg > 0.0))
        return;
    const FrustumPlanes planes = frustumPlanes(view.viewProjection());
    const glm::vec3 eye = glm::vec3(glm::inverse(view.view)[3]);
    const bool lod = lod_error_px > 0.0f && !list.lods.empty();
    const float px_per_rad = pixelsPerRadian(view);
    const double rad_per_ring = ring_deg * (M_PI / 180.0);
    const int last = static_cast<int>(rings.size()) - 1;
    for (size_t ci = 0; ci < list.clusters.size(); ++ci) {
        const DrawCluster& c = list.clusters[ci];
        if (!boxMayBeVisible(planes, c.bounds))
            continue;
        uint32_t count = c.index_count;
        if (lod && px_per_rad > 0.0f) {
            const int level = lodLevelFor(list, c.bounds, eye, px_per_rad, lod_error_px);
            if (level >= 0)
                count = list.lods[static_cast<size_t>(level)].index_count[ci];
        }
        if (count == 0)
            continue;
        const double triangles = count / 3;
        const glm::vec3 centre = 0.5f * (c.bounds.min + c.bounds.max);
        const float radius = 0.5f * glm::length(c.bounds.max - c.bounds.min);
        const glm::vec3 v = centre - eye;
        const float d = glm::length(v);
        double lo = 0.0, hi = M_PI;  // the eye inside the sphere: every direction
        if (d > radius) {
            // In single precision (a cluster's extent is known to far less): the probe runs on
            // the headset's core before every frame.
            const double angle = std::acos(std::clamp(glm::dot(v, axis) / d, -1.0f, 1.0f));
            const double spread = std::asin(std::min(1.0f, radius / d));
            lo = std::max(0.0, angle - spread);
            hi = std::min(M_PI, angle + spread);
        }
        // Spread evenly over the rings [lo, hi] spans.
        const double a = lo / rad_per_ring, b = std::max(a + 1e-9, hi / rad_per_ring);
        const int k0 = std::min(last, static_cast<int>(a));
        const int k1 = std::min(last, static_cast<int>(b));
        // Past the last ring everything falls in it (it is open-ended).
        if (k0 == k1 || k0 == last) {
            rings[static_cast<size_t>(k0)] += triangles;
            continue;
        }
        const double per = triangles / (b - a);
        rings[static_cast<size_t>(k0)] += per * (k0 + 1 - a);
        for (int k = k0 + 1; k < k1; ++k)
            rings[static_cast<size_t>(k)] += per;
        // The last ring also takes the part beyond it.
        rings[static_cast<size_t>(k1)] += per * (b - k1);
    }
}

bool boxInsideCone(const Aabb& box, const glm::vec3& apex, const glm::vec3& axis,
                   float half_angle_rad) {
    if (!(half_angle_rad > 0.0f))
        return false;
    const glm::vec3 centre = 0.5f * (box.min + box.max);
    const float radius = 0.5f * glm::length(box.max - box.min);
    const glm::vec3 v = centre - apex;
    const float d = glm::length(v);
    if (d <= radius * 1.0001f + 1e-6f)
        return false;  // the apex may be inside the sphere
    const float angle = std::acos(std::clamp(glm::dot(v, axis) / d, -1.0f, 1.0f));
    const float spread = std::asin(std::min(1.0f, radius / d));
    // A small absolute slack keeps float rounding on the safe side.
    return angle + spread + 1e-4f <= half_angle_rad;
}

DrawSelection selectDraws(const DrawList& list, const RenderView& view, float lod_error_px) {
    DrawSelection s;
    const FrustumPlanes planes = frustumPlanes(view.viewProjection());
    const bool lod = lod_error_px > 0.0f && !list.lods.empty();
    const bool hole = view.skip_half_angle_rad > 0.0f;
    glm::vec3 eye(0.0f);
    float px_per_rad = 0.0f;
    if (lod) {
        eye = glm::vec3(glm::inverse(view.view)[3]);
        px_per_rad = pixelsPerRadian(view);
    }
    for (size_t ci = 0; ci < list.clusters.size(); ++ci) {
        const DrawCluster& c = list.clusters[ci];
        if (!boxMayBeVisible(planes, c.bounds)) {
            ++s.clusters_culled;
            continue;
        }
        if (hole &&
            boxInsideCone(c.bounds, view.skip_apex, view.skip_axis, view.skip_half_angle_rad)) {
            ++s.clusters_skipped;
            continue;
        }
        ++s.clusters_drawn;
        uint32_t first = c.first_index;
        uint32_t count = c.index_count;
        if (lod && px_per_rad > 0.0f) {
            const int level = lodLevelFor(list, c.bounds, eye, px_per_rad, lod_error_px);
            if (level >= 0) {
                const DrawLodLevel& l = list.lods[static_cast<size_t>(level)];
                first = l.first_index[ci];
                count = l.index_count[ci];
                ++s.clusters_coarsened;
            }
        }
        s.triangles += count / 3;
        if (count == 0)
            continue;
        // Clusters of one batch are adjacent in the index buffer: extend the last draw.
        if (!s.draws.empty() && s.draws.back().batch == c.batch &&
            s.draws.back().first_index + s.draws.back().index_count == first) {
            s.draws.back().index_count += count;
        } else {
            s.draws.push_back({first, count, c.batch});
        }
    }
    return s;
}

}  // namespace qvr
