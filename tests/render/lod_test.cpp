// Vertex-clustering level of detail (draw_list.h, docs/RENDER.md "Level of detail"): each level's
// triangles are the original ones with corners snapped to cell centres, collapsed and repeated
// ones dropped; a view picks per cluster the coarsest level whose half-cell-diagonal move stays
// within lod_error_px of its own pixels at the distance of the cluster's box.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "hand_made_scene.h"
#include "qvr/render/draw_list.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/render/renderer.h"
#include "render_test_util.h"
#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)
#include "qvr/scene/scene_loader.h"
#endif

namespace qvr {
namespace {

constexpr float kHalfCellDiagonal = 0.8660254f;  // √3 / 2

// Appends an n × n grid of quads over [x0, x0 + size] × [z0, z0 + size] whose height follows a
// bump, as one untextured batch: dense, curved geometry that coarse cells collapse.
void addBumpySheet(Scene& s, const glm::vec3& corner, float size, int n) {
    SceneBatch batch;
    batch.first_index = static_cast<uint32_t>(s.indices.size());
    const auto base = static_cast<uint32_t>(s.vertices.size());
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            const float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
            SceneVertex vx;
            vx.position =
                corner + glm::vec3(size * u, 0.1f * size * std::sin(6.0f * u) * std::cos(5.0f * v),
                                   size * v);
            vx.uv = {u, v};
            vx.color = {static_cast<uint8_t>(40 + 200 * u), 120, static_cast<uint8_t>(40 + 200 * v),
                        255};
            s.vertices.push_back(vx);
            batch.bounds.extend(vx.position);
            s.bounds.extend(vx.position);
        }
    }
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            const uint32_t a = base + static_cast<uint32_t>(j * (n + 1) + i);
            const uint32_t b = a + 1, c = a + static_cast<uint32_t>(n + 1), d = c + 1;
            for (uint32_t k : {a, c, d, a, d, b})
                s.indices.push_back(k);
        }
    }
    batch.index_count = static_cast<uint32_t>(s.indices.size()) - batch.first_index;
    s.batches.push_back(batch);
}

// The textured test room with a 2 m sheet of 64 × 64 quads (32 clusters) on its floor.
Scene denseRoom() {
    Scene s = test::texturedRoom();
    s.name = "test:dense-room";
    addBumpySheet(s, {-1.0f, -1.45f, -4.0f}, 2.0f, 64);
    return s;
}

uint64_t trianglesOfClusters(const DrawList& list) {
    uint64_t n = 0;
    for (const DrawCluster& c : list.clusters)
        n += c.index_count / 3;
    return n;
}

uint64_t trianglesOfLevel(const DrawLodLevel& l) {
    uint64_t n = 0;
    for (uint32_t c : l.index_count)
        n += c / 3;
    return n;
}

using Key = std::array<int64_t, 3>;
using KeyTriangle = std::array<Key, 3>;

// The cell holding p, counted from the scene box's corner.
Key cellOf(const glm::vec3& p, const glm::vec3& box_min, float cell_m) {
    const glm::vec3 q = glm::floor((p - box_min) / cell_m);
    return {static_cast<int64_t>(q.x), static_cast<int64_t>(q.y), static_cast<int64_t>(q.z)};
}

// The cell whose centre p is, or a failure when p is not at a cell centre.
::testing::AssertionResult centreCellOf(const glm::vec3& p, const glm::vec3& box_min, float cell_m,
                                        Key& key) {
    const glm::vec3 u = (p - box_min) / cell_m - 0.5f;
    for (int a = 0; a < 3; ++a) {
        const float k = std::round(u[a]);
        if (std::fabs(u[a] - k) > 1e-2f)
            return ::testing::AssertionFailure()
                   << "coordinate " << a << " of (" << p.x << ", " << p.y << ", " << p.z
                   << ") sits at " << u[a] + 0.5f << " cells, not at a cell centre";
        key[static_cast<size_t>(a)] = static_cast<int64_t>(k);
    }
    return ::testing::AssertionSuccess();
}

// One winding of a triangle: the rotation that starts at its smallest corner.
KeyTriangle canonical(const KeyTriangle& t) {
    const size_t lo = static_cast<size_t>(std::min_element(t.begin(), t.end()) - t.begin());
    return {t[lo], t[(lo + 1) % 3], t[(lo + 2) % 3]};
}

// Checks every level of a list against the definition of vertex clustering, computed here
// independently: per cluster, the level's triangles are exactly the distinct non-collapsed
// triangles of cell keys of the original ones; every LOD corner sits at a cell centre within
// half a cell diagonal of each original vertex of that cell; equal cells give equal positions
// everywhere (no cracks); indices point into the scene's vertices plus lod_vertices.
void expectLevelsAreVertexClustering(const DrawList& list, const Scene& scene) {
    const glm::vec3 box_min = scene.bounds.min;
    const size_t vertex_count = scene.vertices.size() + list.lod_vertices.size();
    auto position = [&](uint32_t i) {
        return i < scene.vertices.size() ? scene.vertices[i].position
                                         : list.lod_vertices[i - scene.vertices.size()].position;
    };
    const size_t scene_indices = scene.indices.size();
    for (size_t l = 0; l < list.lods.size(); ++l) {
        const DrawLodLevel& lod = list.lods[l];
        ASSERT_EQ(lod.first_index.size(), list.clusters.size());
        ASSERT_EQ(lod.index_count.size(), list.clusters.size());
        const float cell = lod.cell_m;
        const float max_move = kHalfCellDiagonal * cell * 1.0001f;
        std::map<Key, glm::vec3> centre_of;  // every LOD vertex of this level, by its cell
        // Each batch's original vertices by cell: a LOD vertex keeps the texture and lightmap
        // coordinates and colour of one of them.
        std::map<std::pair<uint32_t, Key>, std::vector<uint32_t>> batch_cell;
        for (const DrawCluster& c : list.clusters)
            for (uint32_t i = c.first_index; i < c.first_index + c.index_count; ++i)
                batch_cell[{c.batch,
                            cellOf(scene.vertices[list.indices[i]].position, box_min, cell)}]
                    .push_back(list.indices[i]);
        for (size_t ci = 0; ci < list.clusters.size(); ++ci) {
            const DrawCluster& c = list.clusters[ci];
            const uint32_t first = lod.first_index[ci], count = lod.index_count[ci];
            ASSERT_EQ(count % 3, 0u);
            ASSERT_GE(first, scene_indices) << "level " << l << " overwrote the scene's indices";
            ASSERT_LE(static_cast<uint64_t>(first) + count, list.indices.size());
            // The reference: the original triangles in cell keys.
            std::set<KeyTriangle> expected;
            std::map<Key, std::vector<glm::vec3>> originals;  // vertices of the cluster by cell
            for (uint32_t i = c.first_index; i < c.first_index + c.index_count; i += 3) {
                KeyTriangle t;
                for (int k = 0; k < 3; ++k) {
                    const glm::vec3 p = scene.vertices[list.indices[i + k]].position;
                    t[static_cast<size_t>(k)] = cellOf(p, box_min, cell);
                    originals[t[static_cast<size_t>(k)]].push_back(p);
                }
                if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
                    expected.insert(canonical(t));
            }
            std::vector<KeyTriangle> got;
            for (uint32_t i = first; i < first + count; i += 3) {
                KeyTriangle t;
                for (int k = 0; k < 3; ++k) {
                    const uint32_t vi = list.indices[i + k];
                    ASSERT_LT(vi, vertex_count) << "level " << l << " cluster " << ci;
                    const glm::vec3 p = position(vi);
                    Key& key = t[static_cast<size_t>(k)];
                    ASSERT_TRUE(centreCellOf(p, box_min, cell, key))
                        << "level " << l << " (cell " << cell << " m) cluster " << ci;
                    auto [it, fresh] = centre_of.try_emplace(key, p);
                    ASSERT_TRUE(fresh || it->second == p)
                        << "cell moved to two positions (a crack), level " << l;
                    const auto orig = originals.find(key);
                    ASSERT_NE(orig, originals.end())
                        << "LOD corner in a cell no original vertex of cluster " << ci << " is in";
                    for (const glm::vec3& o : orig->second)
                        ASSERT_LE(glm::length(o - p), max_move)
                            << "level " << l << " cluster " << ci;
                    const SceneVertex& lv = vi < scene.vertices.size()
                                                ? scene.vertices[vi]
                                                : list.lod_vertices[vi - scene.vertices.size()];
                    const std::vector<uint32_t>& same_cell = batch_cell[{c.batch, key}];
                    ASSERT_TRUE(std::any_of(same_cell.begin(), same_cell.end(), [&](uint32_t o) {
                        const SceneVertex& ov = scene.vertices[o];
                        return ov.uv == lv.uv && ov.lightmap_uv == lv.lightmap_uv &&
                               ov.color == lv.color;
                    })) << "LOD vertex attributes of no original vertex of its batch and cell";
                }
                got.push_back(canonical(t));
            }
            std::sort(got.begin(), got.end());
            ASSERT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end())
                << "a repeated triangle survived, level " << l << " cluster " << ci;
            got.erase(std::unique(got.begin(), got.end()), got.end());
            ASSERT_EQ(got, std::vector<KeyTriangle>(expected.begin(), expected.end()))
                << "level " << l << " cluster " << ci;
        }
    }
}

// Triangles per cluster never grow from the original to the finest level and on to coarser ones;
// cells double.
void expectLevelsShrink(const DrawList& list, const char* what) {
    for (size_t l = 0; l < list.lods.size(); ++l) {
        const DrawLodLevel& lod = list.lods[l];
        if (l > 0) {
            EXPECT_FLOAT_EQ(lod.cell_m, 2.0f * list.lods[l - 1].cell_m) << what;
        }
        for (size_t ci = 0; ci < list.clusters.size(); ++ci) {
            const uint32_t finer =
                l == 0 ? list.clusters[ci].index_count : list.lods[l - 1].index_count[ci];
            EXPECT_LE(lod.index_count[ci], finer) << what << " level " << l << " cluster " << ci;
        }
        const uint64_t finer_total =
            l == 0 ? trianglesOfClusters(list) : trianglesOfLevel(list.lods[l - 1]);
        std::printf("%s level %zu (cell %.4f m): %llu triangles\n", what, l, double(lod.cell_m),
                    static_cast<unsigned long long>(trianglesOfLevel(lod)));
        EXPECT_LE(trianglesOfLevel(lod), finer_total) << what << " level " << l;
    }
}

// A few head poses standing in a scene: its first spawn point turned to several yaws and pitches.
std::vector<Pose> posesIn(const Scene& scene) {
    Pose base;
    if (!scene.spawns.empty())
        base = poseFromSpawn(scene.spawns[0]);
    std::vector<Pose> poses;
    for (double yaw : {0.0, 70.0, 150.0, 250.0}) {
        for (double pitch : {-25.0, 0.0}) {
            Pose p = base;
            p.orientation = base.orientation * quatFromEulerDeg({yaw, pitch, 0.0});
            poses.push_back(p);
        }
    }
    return poses;
}

void expectSameSelection(const DrawSelection& a, const DrawSelection& b) {
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.clusters_drawn, b.clusters_drawn);
    EXPECT_EQ(a.clusters_culled, b.clusters_culled);
    EXPECT_EQ(a.clusters_coarsened, b.clusters_coarsened);
    ASSERT_EQ(a.draws.size(), b.draws.size());
    for (size_t i = 0; i < a.draws.size(); ++i) {
        EXPECT_EQ(a.draws[i].first_index, b.draws[i].first_index) << "draw " << i;
        EXPECT_EQ(a.draws[i].index_count, b.draws[i].index_count) << "draw " << i;
        EXPECT_EQ(a.draws[i].batch, b.draws[i].batch) << "draw " << i;
    }
}

TEST(Lod, LevelsAreVertexClusteringOfTheHandMadeSceneAndNeverAddTriangles) {
    const Scene s = denseRoom();
    ASSERT_TRUE(checkDrawable(s));
    DrawList list = buildDrawList(s);
    buildLods(list, s);
    ASSERT_EQ(list.lods.size(), 6u);
    const float diagonal = glm::length(s.bounds.max - s.bounds.min);
    EXPECT_FLOAT_EQ(list.lods[0].cell_m, diagonal / 4096.0f);
    expectLevelsShrink(list, "dense room");
    expectLevelsAreVertexClustering(list, s);
    // The sheet's 3 cm quads collapse under the coarsest (7 cm) cells; the room's walls do not.
    EXPECT_LT(trianglesOfLevel(list.lods.back()), trianglesOfClusters(list) / 2);
    // LOD indices follow the scene's, which stay as buildDrawList left them.
    const DrawList plain = buildDrawList(s);
    ASSERT_GT(list.indices.size(), plain.indices.size());
    EXPECT_TRUE(std::equal(plain.indices.begin(), plain.indices.end(), list.indices.begin()));
}

TEST(Lod, ExplicitCellsFollowTheOptions) {
    const Scene s = denseRoom();
    DrawList list = buildDrawList(s);
    LodOptions o;
    o.levels = 3;
    o.finest_cell_m = 0.05f;
    buildLods(list, s, o);
    ASSERT_EQ(list.lods.size(), 3u);
    EXPECT_FLOAT_EQ(list.lods[0].cell_m, 0.05f);
    EXPECT_FLOAT_EQ(list.lods[2].cell_m, 0.2f);
    expectLevelsShrink(list, "dense room, 5 cm cells");
    expectLevelsAreVertexClustering(list, s);
}

TEST(Lod, BuildingAgainReplacesTheEarlierLevels) {
    const Scene s = denseRoom();
    DrawList once = buildDrawList(s);
    buildLods(once, s);
    DrawList twice = buildDrawList(s);
    buildLods(twice, s);
    buildLods(twice, s);
    // Something else in between, then the default again.
    DrawList thrice = buildDrawList(s);
    LodOptions coarse;
    coarse.levels = 2;
    coarse.finest_cell_m = 0.3f;
    buildLods(thrice, s, coarse);
    buildLods(thrice, s);
    for (const DrawList* other : {&twice, &thrice}) {
        EXPECT_EQ(other->indices, once.indices);
        ASSERT_EQ(other->lod_vertices.size(), once.lod_vertices.size());
        for (size_t i = 0; i < once.lod_vertices.size(); ++i)
            ASSERT_EQ(other->lod_vertices[i].position, once.lod_vertices[i].position) << i;
        ASSERT_EQ(other->lods.size(), once.lods.size());
        for (size_t l = 0; l < once.lods.size(); ++l) {
            EXPECT_EQ(other->lods[l].cell_m, once.lods[l].cell_m);
            EXPECT_EQ(other->lods[l].first_index, once.lods[l].first_index);
            EXPECT_EQ(other->lods[l].index_count, once.lods[l].index_count);
        }
    }
    // No levels asked for: back to the plain list.
    LodOptions none;
    none.levels = 0;
    buildLods(twice, s, none);
    EXPECT_EQ(twice.indices, buildDrawList(s).indices);
    EXPECT_TRUE(twice.lods.empty());
    EXPECT_TRUE(twice.lod_vertices.empty());
}

TEST(Lod, EmptyAndDegenerateScenesGiveNoLevelsAndNoCrash) {
    const HmdProfile profile = test::smallProfile();
    const RenderView v = fullFrameView(profile, Pose{}, Eye::kLeft);
    Scene empty;
    DrawList list = buildDrawList(empty);
    buildLods(list, empty);
    EXPECT_TRUE(list.lods.empty());
    EXPECT_TRUE(list.indices.empty());
    const DrawSelection sel = selectDraws(list, v, 1.0f);
    EXPECT_EQ(sel.triangles, 0u);
    EXPECT_TRUE(sel.draws.empty());

    // Vertices but no batches, and a scene whose every vertex is one point (no extent, no cell).
    Scene loose;
    loose.vertices.resize(3);
    list = buildDrawList(loose);
    buildLods(list, loose);
    EXPECT_TRUE(list.lods.empty());
    Scene point;
    test::addQuad(point, {0, 0, -2}, {1, 0, -2}, {1, 1, -2}, {0, 1, -2}, -1, -1, {255, 0, 0, 255});
    for (SceneVertex& vx : point.vertices)
        vx.position = {0.0f, 0.0f, -2.0f};
    point.bounds = Aabb{};
    point.bounds.extend({0.0f, 0.0f, -2.0f});
    list = buildDrawList(point);
    buildLods(list, point);
    EXPECT_TRUE(list.lods.empty());
    EXPECT_EQ(selectDraws(list, v, 1.0f).triangles, 2u);
}

TEST(Lod, NoErrorBudgetSelectsExactlyWhatAListWithoutLevelsSelects) {
    const Scene s = denseRoom();
    const DrawList plain = buildDrawList(s);
    DrawList with_lods = plain;
    buildLods(with_lods, s);
    ASSERT_FALSE(with_lods.lods.empty());
    const HmdProfile profile = test::smallProfile();
    int coarsened_somewhere = 0;
    for (const Pose& head : posesIn(s)) {
        const RenderView v = fullFrameView(profile, head, Eye::kLeft);
        const DrawSelection reference = selectDraws(plain, v);
        for (float off : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN()}) {
            SCOPED_TRACE(::testing::Message() << "lod_error_px " << off);
            const DrawSelection sel = selectDraws(with_lods, v, off);
            expectSameSelection(sel, reference);
            EXPECT_EQ(sel.clusters_coarsened, 0u);
        }
        // And the budget does something on this list, so the equality above is not vacuous.
        coarsened_somewhere += static_cast<int>(selectDraws(with_lods, v, 1.0f).clusters_coarsened);
        // A list without levels ignores the budget.
        expectSameSelection(selectDraws(plain, v, 4.0f), reference);
    }
    EXPECT_GT(coarsened_somewhere, 0);
}

// What selectDraws picks for a one-cluster list, as a level (−1 = the original triangles).
int selectedLevel(const DrawList& list, const DrawSelection& sel) {
    if (sel.clusters_drawn != 1)
        return -2;
    if (sel.clusters_coarsened == 0)
        return sel.draws.size() == 1 && sel.draws[0].first_index == list.clusters[0].first_index
                   ? -1
                   : -2;
    for (size_t l = 0; l < list.lods.size(); ++l) {
        if (list.lods[l].index_count[0] == 0 && sel.draws.empty() && sel.triangles == 0)
            return static_cast<int>(l);  // may be any vanished level; the caller checks counts
        if (sel.draws.size() == 1 && sel.draws[0].first_index == list.lods[l].first_index[0] &&
            sel.draws[0].index_count == list.lods[l].index_count[0])
            return static_cast<int>(l);
    }
    return -2;
}

TEST(Lod, TheLevelFollowsTheDistanceToTheClusterBoxInTheViewsPixels) {
    // One cluster: a 0.4 m sheet of 8 × 8 quads below and right of the line of sight, at depth d.
    const HmdProfile profile = test::smallProfile();
    const double px_per_rad = std::max(profile.focalXPx(), profile.focalYPx());
    LodOptions o;
    o.finest_cell_m = 0.01f;  // 1, 2, 4, 8, 16, 32 cm
    int previous = -1;
    int levels_seen = 0;
    for (double d = 0.3; d < 150.0; d *= 1.25) {
        Scene s;
        addBumpySheet(s, {0.1f, -0.3f, static_cast<float>(-d) - 0.4f}, 0.4f, 8);
        DrawList list = buildDrawList(s);
        ASSERT_EQ(list.clusters.size(), 1u);
        buildLods(list, s, o);
        ASSERT_EQ(list.lods.size(), 6u);
        const Pose head;  // at the origin, looking down −z
        const RenderView v = fullFrameView(profile, head, Eye::kLeft, CameraOptions{0.0});
        // The nearest point of the cluster's box to the eye, not its centre.
        const Aabb& box = list.clusters[0].bounds;
        const glm::dvec3 nearest =
            glm::clamp(glm::dvec3(0.0), glm::dvec3(box.min), glm::dvec3(box.max));
        const double distance = glm::length(nearest);
        for (float err : {0.5f, 1.0f, 3.0f}) {
            // Coarsest level whose half-cell diagonal, seen at `distance`, is ≤ err pixels.
            const double max_cell = err * distance / (kHalfCellDiagonal * px_per_rad);
            int expected = -1;
            bool near_boundary = false;
            for (size_t l = 0; l < list.lods.size(); ++l) {
                near_boundary |= std::fabs(list.lods[l].cell_m / max_cell - 1.0) < 0.01;
                if (list.lods[l].cell_m <= max_cell)
                    expected = static_cast<int>(l);
            }
            if (near_boundary)
                continue;
            const DrawSelection sel = selectDraws(list, v, err);
            const int got = selectedLevel(list, sel);
            const uint32_t expected_count = expected < 0
                                                ? list.clusters[0].index_count
                                                : list.lods[size_t(expected)].index_count[0];
            EXPECT_EQ(sel.triangles, expected_count / 3) << "d " << d << " err " << err;
            if (expected_count > 0) {
                EXPECT_EQ(got, expected) << "d " << d << " m, err " << err << " px";
            }
            if (err == 1.0f) {
                EXPECT_GE(expected, previous) << "a farther view picked a finer level";
                if (expected != previous)
                    ++levels_seen;
                previous = expected;
            }
        }
    }
    // From the original triangles near by to the coarsest level far away.
    EXPECT_EQ(previous, 5);
    EXPECT_EQ(levels_seen, 6);
}

TEST(Lod, AnEyeInsideTheClusterBoxGetsTheOriginalTriangles) {
    Scene s;
    addBumpySheet(s, {-1.0f, -0.5f, -1.0f}, 2.0f, 8);  // box spans the origin in x and z
    s.bounds.extend({0.0f, 0.5f, 0.0f});
    DrawList list = buildDrawList(s);
    LodOptions o;
    o.finest_cell_m = 0.01f;
    buildLods(list, s, o);
    Pose head;
    head.position_m = {0.0f, -0.45f, 0.0f};
    head.orientation = quatFromEulerDeg({0.0, -30.0, 0.0});
    const RenderView v = fullFrameView(test::smallProfile(), head, Eye::kLeft, CameraOptions{0.0});
    const DrawSelection sel = selectDraws(list, v, 1000.0f);
    EXPECT_EQ(sel.clusters_coarsened, 0u);
    EXPECT_EQ(sel.triangles, 128u);
}

// A lower-resolution view of the same pose has larger pixels: it never draws more triangles.
void expectFewerPixelsNeverDrawMore(const Scene& s, bool strictly_somewhere) {
    DrawList list = buildDrawList(s);
    buildLods(list, s);
    const HmdProfile profile = test::smallProfile();
    bool strictly = false;
    for (const Pose& head : posesIn(s)) {
        const RenderView low = fullFrameView(profile, head, Eye::kRight);
        RenderView high = low;  // the same frustum on 4 × 4 times the pixels
        high.width_px *= 4;
        high.height_px *= 4;
        LayerRect half;  // the same full field at scale 2
        half.rect = {0, 0, profile.width_px, profile.height_px};
        half.scale = 2.0;
        half.width_px = profile.width_px / 2;
        half.height_px = profile.height_px / 2;
        const RenderView lower = layerView(profile, head, Eye::kRight, half);
        for (float err : {0.5f, 1.0f, 2.0f}) {
            const DrawSelection h = selectDraws(list, high, err);
            const DrawSelection m = selectDraws(list, low, err);
            const DrawSelection l = selectDraws(list, lower, err);
            EXPECT_LE(m.triangles, h.triangles) << "err " << err;
            EXPECT_LE(l.triangles, m.triangles) << "err " << err;
            EXPECT_GE(m.clusters_coarsened, h.clusters_coarsened);
            EXPECT_EQ(m.clusters_drawn, h.clusters_drawn);
            strictly |= m.triangles < h.triangles && l.triangles < m.triangles;
            // A larger budget never draws more either.
            EXPECT_LE(selectDraws(list, low, 2.0f * err).triangles, m.triangles);
            // And a budget never draws more than no budget.
            EXPECT_LE(h.triangles, selectDraws(list, high, 0.0f).triangles);
        }
    }
    if (strictly_somewhere) {
        EXPECT_TRUE(strictly) << s.name << ": resolution never changed the triangles drawn";
    }
}

TEST(Lod, ALowerResolutionViewDrawsNoMoreTriangles) {
    expectFewerPixelsNeverDrawMore(denseRoom(), true);
}

#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)

const Scene& builtinRoom() {
    static const Scene scene = [] {
        auto s = loadScene("builtin:room");
        EXPECT_TRUE(s) << s.error();
        return s ? std::move(s).value() : Scene{};
    }();
    return scene;
}

TEST(Lod, LevelsOfBuiltinRoomAreVertexClusteringAndShrink) {
    const Scene& s = builtinRoom();
    ASSERT_FALSE(s.vertices.empty());
    ASSERT_TRUE(s.bounds.valid());
    DrawList list = buildDrawList(s);
    buildLods(list, s);
    ASSERT_EQ(list.lods.size(), 6u);
    expectLevelsShrink(list, "builtin:room");
    expectLevelsAreVertexClustering(list, s);
    EXPECT_LT(trianglesOfLevel(list.lods.back()), trianglesOfClusters(list));
}

TEST(Lod, ALowerResolutionViewOfBuiltinRoomDrawsFewerTriangles) {
    const Scene& s = builtinRoom();
    ASSERT_FALSE(s.spawns.empty());
    expectFewerPixelsNeverDrawMore(s, true);
    // At the spawn point itself, strictly.
    DrawList list = buildDrawList(s);
    buildLods(list, s);
    const HmdProfile profile = test::smallProfile();
    const RenderView low = fullFrameView(profile, poseFromSpawn(s.spawns[0]), Eye::kLeft);
    RenderView high = low;
    high.width_px *= 4;
    high.height_px *= 4;
    const uint64_t t_low = selectDraws(list, low, 1.0f).triangles;
    const uint64_t t_high = selectDraws(list, high, 1.0f).triangles;
    const uint64_t t_none = selectDraws(list, low, 0.0f).triangles;
    std::printf(
        "builtin:room at its spawn, 1 px: %llu triangles at 320x360, %llu at 1280x1440, "
        "%llu without LOD\n",
        static_cast<unsigned long long>(t_low), static_cast<unsigned long long>(t_high),
        static_cast<unsigned long long>(t_none));
    EXPECT_LT(t_low, t_high);
    EXPECT_LE(t_high, t_none);
}

TEST(GlLod, OnePixelOfErrorDrawsFewerPrimitivesAndNearlyTheSameImage) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    GlRendererOptions options;
    options.lod_error_px = 1.0f;
    auto lod = GlRenderer::create(options);
    ASSERT_TRUE(lod) << lod.error();
    const Scene& s = builtinRoom();
    ASSERT_TRUE(gl->upload(s));
    ASSERT_TRUE((*lod)->upload(s));
    DrawList list = buildDrawList(s);
    buildLods(list, s);
    const HmdProfile profile = test::smallProfile();
    const Pose spawn = poseFromSpawn(s.spawns[0]);
    for (double pitch : {-10.0, -40.0}) {
        Pose head = spawn;
        head.orientation = spawn.orientation * quatFromEulerDeg({0.0, pitch, 0.0});
        const RenderView v = fullFrameView(profile, head, Eye::kLeft);
        ImageRgba8 exact, coarse;
        auto e = gl->render(v, exact);
        auto c = (*lod)->render(v, coarse);
        ASSERT_TRUE(e) << e.error();
        ASSERT_TRUE(c) << c.error();
        // The GL renderer draws what selectDraws picks for its budget, from its LOD buffers.
        EXPECT_EQ(c->primitives_generated, selectDraws(list, v, 1.0f).triangles);
        EXPECT_EQ(e->primitives_generated, selectDraws(list, v, 0.0f).triangles);
        EXPECT_LT(c->primitives_generated, e->primitives_generated) << "pitch " << pitch;
        // The yardstick: the exact image against itself moved by one whole pixel. No vertex of
        // the LOD image moved by more than a pixel and most moved less, so it must be closer to
        // the exact image than that. Measured: LOD 28-30 dB / 2.2-2.7 levels, one-pixel shift
        // 25.7-26.5 dB / 4.3-5.5 levels.
        const int w = exact.width() - 1, h = exact.height();
        const ImageRgba8 left = test::crop(exact, 0, 0, w, h);
        const ImageRgba8 right = test::crop(exact, 1, 0, w, h);
        const double psnr = test::psnrDb(exact, coarse);
        const double mad = test::meanAbsDiff(exact, coarse);
        const double shift_psnr = test::psnrDb(left, right);
        const double shift_mad = test::meanAbsDiff(left, right);
        std::printf(
            "builtin:room pitch %.0f, LOD 1 px: %llu of %llu primitives; PSNR %.1f dB, "
            "mean |diff| %.2f levels (one-pixel shift: %.1f dB, %.2f levels)\n",
            pitch, static_cast<unsigned long long>(c->primitives_generated),
            static_cast<unsigned long long>(e->primitives_generated), psnr, mad, shift_psnr,
            shift_mad);
        EXPECT_GT(psnr, shift_psnr);
        EXPECT_LT(mad, shift_mad);
        EXPECT_GT(psnr, 25.0);
    }
}

#endif  // QVR_RENDER_HAVE_SCENE_LIBRARY

TEST(GlLod, ANegativeOrNanErrorBudgetIsAnErrorWithAMessage) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    for (float bad : {-1.0f, -0.001f, std::numeric_limits<float>::quiet_NaN(), 1e6f,
                      std::numeric_limits<float>::infinity()}) {
        GlRendererOptions options;
        options.lod_error_px = bad;
        auto r = GlRenderer::create(options);
        ASSERT_FALSE(r) << "lod_error_px " << bad;
        EXPECT_NE(r.error().find("LOD"), std::string::npos) << r.error();
    }
}

}  // namespace
}  // namespace qvr
