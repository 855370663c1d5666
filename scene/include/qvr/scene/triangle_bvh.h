// The "hardware intermediate data" LIWC reads before rendering (paper §4.1): how many of the
// scene's triangles a view processes, in total and by eccentricity ring around the gaze.
// Counted on the CPU against a bounding-volume hierarchy built once per scene; brute-force
// twins define the same counts by testing every triangle, for tests.
//
// Definitions (docs/SCENE.md):
// - A triangle is processed by a view when it intersects the view frustum (the closed convex
//   region between the near and far planes inside the four side planes). That is the set of
//   triangles OpenGL's clipper does not discard; back faces count (culling comes later).
// - Its eccentricity is the smallest angle, seen from the eye, between the gaze direction and
//   any point of the part of the triangle inside the frustum (0 when the gaze ray hits it).
// - A cone of half-angle e contains a triangle when that eccentricity is ≤ e, i.e. the triangle
//   intersects the cone (apex at the eye); a triangle falls in ring k = ⌊eccentricity / ring⌋
//   (the last ring also collects everything beyond). So the prefix sum of trianglesPerRing up to
//   ring k equals the frustum-clipped cone count at (k + 1)·ring.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "qvr/scene/scene.h"

namespace qvr {

// An eye's view: position and orientation (eye-to-world; the eye looks down its −z, y up), and
// an off-axis perspective projection given by the tangents of its four edge angles, the form
// OpenXR's XrFovf and glFrustum(l·n, r·n, b·n, t·n, n, f) use.
struct EyeView {
    glm::dvec3 position_m{0.0};
    glm::dquat orientation{1.0, 0.0, 0.0, 0.0};
    double tan_left = 1.0;   // tangent of the left edge angle (positive = left of axis)
    double tan_right = 1.0;  // right of axis
    double tan_down = 1.0;
    double tan_up = 1.0;
    double near_m = 0.05;
    double far_m = 1000.0;

    // A symmetric frustum with the given full fields of view, as the HMD profile states them.
    static EyeView symmetric(const glm::dvec3& position_m, const glm::dquat& orientation,
                             double fov_h_deg, double fov_v_deg, double near_m, double far_m);
};

// A view cone with apex at the eye: everything within half_angle_deg of the axis, optionally
// limited to distances along the axis in [near_m, far_m] (no limit by default).
struct ViewCone {
    glm::dvec3 apex_m{0.0};
    glm::dvec3 direction{0.0, 0.0, -1.0};  // world space, need not be normalized
    double half_angle_deg = 10.0;          // (0, 90)
    double near_m = 0.0;
    double far_m = 1e30;
};

// What one query cost: for benchmarks and for checking that traversal prunes.
struct BvhQueryStats {
    uint64_t nodes_visited = 0;
    uint64_t nodes_accepted_whole = 0;  // subtrees counted without visiting their triangles
    uint64_t triangles_tested = 0;      // exact per-triangle tests
};

// Built once per scene; queries are const and may run concurrently from several threads.
class TriangleBvh {
public:
    // Builds over the scene's triangles (positions copied; the scene may go away afterwards).
    explicit TriangleBvh(const Scene& scene);
    TriangleBvh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices);

    size_t triangleCount() const { return m_tri_count; }
    size_t nodeCount() const { return m_nodes.size(); }

    // Triangles intersecting the cone.
    uint64_t countTrianglesInCone(const ViewCone& cone, BvhQueryStats* stats = nullptr) const;
    // Triangles intersecting the frustum.
    uint64_t countTrianglesInFrustum(const EyeView& view, BvhQueryStats* stats = nullptr) const;
    // Triangles intersecting the frustum by ring of eccentricity around gaze_dir_eye (a direction
    // in eye space, e.g. EyeGeometry::gazeDirection): rings entries, ring k covering
    // [k·ring_deg, (k + 1)·ring_deg), the last one open-ended.
    std::vector<uint64_t> trianglesPerRing(const EyeView& view, const glm::dvec3& gaze_dir_eye,
                                           double ring_deg, int rings,
                                           BvhQueryStats* stats = nullptr) const;

    // Brute-force twins: the same definitions, every triangle tested.
    uint64_t countTrianglesInConeBruteForce(const ViewCone& cone) const;
    uint64_t countTrianglesInFrustumBruteForce(const EyeView& view) const;
    std::vector<uint64_t> trianglesPerRingBruteForce(const EyeView& view,
                                                     const glm::dvec3& gaze_dir_eye,
                                                     double ring_deg, int rings) const;

    // What a GPU's trivial-reject test keeps: triangles not having all three vertices outside
    // one frustum plane (clip-space outcodes). A superset of countTrianglesInFrustum (it adds
    // triangles that pass beside a frustum corner); the two bracket what a clipper-stage
    // pipeline-statistics query reports. Brute force; for cross-checks against OpenGL.
    uint64_t countTrianglesByOutcodes(const EyeView& view) const;

private:
    struct Node {
        glm::vec3 min, max;
        uint32_t begin = 0, end = 0;  // the subtree's triangles, contiguous in BVH order
        uint32_t left = 0;            // inner: left child (right = left + 1); leaf: 0
    };
    void build(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices);

    std::vector<Node> m_nodes;
    std::vector<glm::vec3> m_tri;  // 3 vertices per triangle, in BVH order
    size_t m_tri_count = 0;
};

}  // namespace qvr
