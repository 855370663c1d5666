// The draw list: clusters that partition each batch's triangles, bounds that hold them, and
// culling that drops what a view cannot see without ever dropping what it can.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "hand_made_scene.h"
#include "qvr/render/draw_list.h"
#include "qvr/render/renderer.h"
#include "render_test_util.h"

namespace qvr {
namespace {

// A 40 m × 40 m floor of 100 × 100 quads as ONE batch, like a Quake III level's per-texture
// batch, then a few small quads as batches of their own.
Scene bigFloor() {
    Scene s;
    s.name = "test:floor";
    SceneBatch floor;
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> shuffle(0, 1);
    const int n = 100;
    for (int z = 0; z <= n; ++z) {
        for (int x = 0; x <= n; ++x) {
            SceneVertex v;
            v.position = {-20.0f + 40.0f * x / n, -1.5f, -38.0f + 40.0f * z / n};
            s.vertices.push_back(v);
            floor.bounds.extend(v.position);
        }
    }
    for (int z = 0; z < n; ++z) {
        for (int x = 0; x < n; ++x) {
            const uint32_t a = static_cast<uint32_t>(z * (n + 1) + x);
            const uint32_t b = a + 1, c = a + static_cast<uint32_t>(n + 1), d = c + 1;
            for (uint32_t i : {a, b, d, a, d, c})
                s.indices.push_back(i);
        }
    }
    floor.index_count = static_cast<uint32_t>(s.indices.size());
    s.batches.push_back(floor);
    s.bounds = floor.bounds;
    for (int i = 0; i < 5; ++i) {
        const float x = -10.0f + 5.0f * i;
        test::addQuad(s, {x, 0, -5}, {x + 1, 0, -5}, {x + 1, 1, -5}, {x, 1, -5}, -1, -1,
                      {255, 255, 255, 255});
    }
    return s;
}

using Tri = std::array<uint32_t, 3>;

std::vector<Tri> trianglesOf(const std::vector<uint32_t>& indices, uint32_t first, uint32_t count) {
    std::vector<Tri> t;
    for (uint32_t i = first; i < first + count; i += 3)
        t.push_back({indices[i], indices[i + 1], indices[i + 2]});
    std::sort(t.begin(), t.end());
    return t;
}

TEST(DrawList, ClustersPartitionEachBatchAndBoundTheirTriangles) {
    const Scene s = bigFloor();
    ASSERT_TRUE(checkDrawable(s));
    const DrawList list = buildDrawList(s, 256);
    ASSERT_EQ(list.indices.size(), s.indices.size());
    // Each batch's range holds the same triangles as before, reordered.
    for (const SceneBatch& b : s.batches)
        EXPECT_EQ(trianglesOf(list.indices, b.first_index, b.index_count),
                  trianglesOf(s.indices, b.first_index, b.index_count));
    // Clusters tile the index buffer in order, stay within their batch, hold ≤ 256 triangles.
    uint32_t next = 0;
    for (const DrawCluster& c : list.clusters) {
        EXPECT_EQ(c.first_index, next);
        next = c.first_index + c.index_count;
        const SceneBatch& b = s.batches[c.batch];
        EXPECT_GE(c.first_index, b.first_index);
        EXPECT_LE(next, b.first_index + b.index_count);
        EXPECT_LE(c.index_count, 3u * 256u);
        for (uint32_t i = c.first_index; i < next; ++i) {
            const glm::vec3 p = s.vertices[list.indices[i]].position;
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, c.bounds.min)) &&
                        glm::all(glm::lessThanEqual(p, c.bounds.max)));
        }
    }
    EXPECT_EQ(next, s.indices.size());
    EXPECT_EQ(list.clusters.size(), 20000u / 256u + 1u + 5u);
    // Morton order keeps clusters compact: 128 quads of 0.4 m cover ~20 m² when square; a
    // cluster straddling a jump of the curve spans more, but on average they stay small.
    double mean_extent = 0.0;
    for (const DrawCluster& c : list.clusters) {
        const glm::vec3 e = c.bounds.max - c.bounds.min;
        mean_extent += std::max(e.x, e.z) / static_cast<double>(list.clusters.size());
    }
    EXPECT_LT(mean_extent, 10.0);
}

TEST(DrawList, CullingKeepsEveryTriangleTheViewReaches) {
    const Scene s = bigFloor();
    const DrawList list = buildDrawList(s);
    const HmdProfile profile = test::smallProfile();
    // A narrow layer looking down at part of the floor: most clusters are culled, but every
    // triangle with a vertex inside the frustum is in a drawn cluster.
    LayerRect l;
    l.rect = {100, 220, 220, 340};
    l.scale = 1.0;
    l.width_px = l.height_px = 120;
    for (double yaw : {0.0, 45.0, 170.0}) {
        Pose head;
        head.orientation = quatFromEulerDeg({yaw, -20.0, 0.0});
        const RenderView v = layerView(profile, head, Eye::kLeft, l);
        const DrawSelection sel = selectDraws(list, v);
        EXPECT_LT(sel.triangles, s.triangleCount() / 4) << "yaw " << yaw;
        std::vector<bool> drawn(s.indices.size() / 3, false);
        for (const DrawRange& d : sel.draws) {
            for (uint32_t i = d.first_index; i < d.first_index + d.index_count; i += 3)
                drawn[i / 3] = true;
        }
        const glm::mat4 vp = v.viewProjection();
        int reached = 0;
        for (size_t t = 0; t < drawn.size(); ++t) {
            for (int k = 0; k < 3; ++k) {
                const glm::vec4 c = vp * glm::vec4(s.vertices[list.indices[3 * t + k]].position, 1);
                if (c.w > 0 && std::abs(c.x) <= c.w && std::abs(c.y) <= c.w &&
                    std::abs(c.z) <= c.w) {
                    EXPECT_TRUE(drawn[t]) << "triangle " << t << " yaw " << yaw;
                    ++reached;
                    break;
                }
            }
        }
        EXPECT_GT(reached, 0) << "yaw " << yaw;
    }
}

TEST(DrawList, MalformedScenesAreRejectedBeforeDrawing) {
    Scene s = bigFloor();
    s.batches[0].index_count -= 1;
    EXPECT_FALSE(checkDrawable(s));
    s = bigFloor();
    s.batches[1].texture = -2;
    EXPECT_FALSE(checkDrawable(s));
    s = bigFloor();
    s.indices.back() = static_cast<uint32_t>(s.vertices.size());
    EXPECT_FALSE(checkDrawable(s));
    auto null_renderer = makeNullRenderer();
    EXPECT_FALSE(null_renderer->upload(s));
}

}  // namespace
}  // namespace qvr
