// BVH over a scene's triangles and the exact per-triangle tests behind LIWC's triangle counts
// (paper §4.1). A node is rejected, or accepted whole, only when its bounding box / sphere
// proves it; everything else reaches the same exact per-triangle test the brute-force twins
// use, so both give identical counts.
#include "qvr/scene/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

#include "qvr/core/check.h"

namespace qvr {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerDeg = kPi / 180.0;
constexpr uint32_t kLeafTriangles = 4;
// Node-level decisions keep this far (radians) from ring and cone boundaries, so rounding in
// the bound computations can never disagree with the per-triangle test.
constexpr double kAngleMargin = 1e-7;
constexpr int kMaxClipVertices = 16;

struct Plane {
    glm::dvec3 n;
    double d;  // inside: dot(n, p) + d ≥ 0
    double distance(const glm::dvec3& p) const { return glm::dot(n, p) + d; }
};

struct Polygon {
    std::array<glm::dvec3, kMaxClipVertices> v;
    int count = 0;
};

// Sutherland–Hodgman against one plane; keeps the closed inside half-space.
void clip(Polygon& poly, const Plane& plane) {
    if (poly.count == 0)
        return;
    Polygon out;
    for (int i = 0; i < poly.count; ++i) {
        const glm::dvec3& a = poly.v[static_cast<size_t>(i)];
        const glm::dvec3& b = poly.v[static_cast<size_t>((i + 1) % poly.count)];
        const double da = plane.distance(a), db = plane.distance(b);
        if (da >= 0.0)
            out.v[static_cast<size_t>(out.count++)] = a;
        if ((da >= 0.0) != (db >= 0.0)) {
            const double t = da / (da - db);
            out.v[static_cast<size_t>(out.count++)] = a + t * (b - a);
        }
    }
    poly = out;
}

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// Smallest angle (radians) between the unit direction g and the directions from the origin to
// points of the convex planar polygon, all of which lie strictly on one side of a plane through
// the origin (in front of the eye), or at the origin (angle 0).
double minAngle(const Polygon& poly, const glm::dvec3& g) {
    const int n = poly.count;
    for (int i = 0; i < n; ++i) {
        if (glm::dot(poly.v[static_cast<size_t>(i)], poly.v[static_cast<size_t>(i)]) < 1e-24)
            return 0.0;
    }
    if (n >= 3) {
        // Does the gaze ray hit the polygon? Newell normal, ray-plane hit, edge tests.
        glm::dvec3 normal(0.0);
        for (int i = 0; i < n; ++i) {
            const glm::dvec3& a = poly.v[static_cast<size_t>(i)];
            const glm::dvec3& b = poly.v[static_cast<size_t>((i + 1) % n)];
            normal += glm::cross(a, b);
        }
        const double ng = glm::dot(normal, g);
        if (std::fabs(ng) > 1e-300) {
            const double t = glm::dot(normal, poly.v[0]) / ng;
            if (t > 0.0) {
                const glm::dvec3 p = t * g;
                bool inside = true;
                for (int i = 0; i < n && inside; ++i) {
                    const glm::dvec3& a = poly.v[static_cast<size_t>(i)];
                    const glm::dvec3& b = poly.v[static_cast<size_t>((i + 1) % n)];
                    inside = glm::dot(glm::cross(b - a, p - a), normal) >= 0.0;
                }
                if (inside)
                    return 0.0;
            }
        }
    }
    // Otherwise the nearest direction lies on an edge: the great-circle arc between its ends.
    double best = kPi;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3& a = poly.v[static_cast<size_t>(i)];
        const glm::dvec3& b = poly.v[static_cast<size_t>((i + 1) % n)];
        best = std::min(best, angleBetween(g, a));
        const glm::dvec3 c = glm::cross(a, b);
        const double cl = glm::length(c);
        if (cl < 1e-300)
            continue;
        const glm::dvec3 cn = c / cl;
        const double off = glm::dot(g, cn);
        const glm::dvec3 gp = g - off * cn;  // g projected into the arc's plane
        if (glm::dot(glm::cross(a, gp), cn) >= 0.0 && glm::dot(glm::cross(gp, b), cn) >= 0.0 &&
            glm::dot(gp, a + b) > 0.0)
            best = std::min(best, std::atan2(std::fabs(off), glm::length(gp)));
    }
    return best;
}

// Eye-space frustum planes, inside = dot(n, p) + d ≥ 0 (eye looks down −z).
std::array<Plane, 6> eyeFrustum(const EyeView& v) {
    return {Plane{{0, 0, -1}, -v.near_m},  Plane{{0, 0, 1}, v.far_m},
            Plane{{1, 0, -v.tan_left}, 0}, Plane{{-1, 0, -v.tan_right}, 0},
            Plane{{0, 1, -v.tan_down}, 0}, Plane{{0, -1, -v.tan_up}, 0}};
}

// The same planes in world space.
std::array<Plane, 6> worldFrustum(const EyeView& v) {
    std::array<Plane, 6> planes = eyeFrustum(v);
    for (Plane& p : planes) {
        p.n = v.orientation * p.n;
        p.d -= glm::dot(p.n, v.position_m);
    }
    return planes;
}

void checkView(const EyeView& v) {
    QVR_CHECK_MSG(v.near_m > 0.0 && v.far_m > v.near_m, "EyeView needs 0 < near < far");
    QVR_CHECK_MSG(v.tan_left + v.tan_right > 0.0 && v.tan_down + v.tan_up > 0.0,
                  "EyeView frustum is empty");
}

// The part of a world-space triangle inside the frustum, in eye space.
Polygon clipToView(const glm::vec3* tri, const EyeView& view, const std::array<Plane, 6>& eye) {
    const glm::dquat inv = glm::conjugate(view.orientation);
    Polygon poly;
    poly.count = 3;
    for (int k = 0; k < 3; ++k)
        poly.v[static_cast<size_t>(k)] = inv * (glm::dvec3(tri[k]) - view.position_m);
    for (const Plane& p : eye)
        clip(poly, p);
    return poly;
}

struct ConeFrame {
    glm::dvec3 apex;
    glm::dvec3 axis;  // unit
    double half_angle;
    double near_m, far_m;
};

ConeFrame coneFrame(const ViewCone& c) {
    QVR_CHECK_MSG(c.half_angle_deg > 0.0 && c.half_angle_deg < 90.0,
                  "cone half-angle must be in (0, 90) degrees");
    QVR_CHECK_MSG(glm::length(c.direction) > 0.0, "cone direction is zero");
    QVR_CHECK_MSG(c.near_m >= 0.0 && c.far_m > c.near_m, "cone needs 0 ≤ near < far");
    return {c.apex_m, glm::normalize(c.direction), c.half_angle_deg * kRadPerDeg, c.near_m,
            c.far_m};
}

bool triangleInCone(const glm::vec3* tri, const ConeFrame& c) {
    Polygon poly;
    poly.count = 3;
    for (int k = 0; k < 3; ++k)
        poly.v[static_cast<size_t>(k)] = glm::dvec3(tri[k]) - c.apex;
    clip(poly, Plane{c.axis, -c.near_m});
    clip(poly, Plane{-c.axis, c.far_m});
    if (poly.count == 0)
        return false;
    return minAngle(poly, c.axis) <= c.half_angle;
}

int ringOf(double angle_rad, double ring_rad, int rings) {
    const double k = std::floor(angle_rad / ring_rad);
    return k >= static_cast<double>(rings - 1) ? rings - 1 : static_cast<int>(k);
}

// The range of angles from axis (unit) under which a bounding sphere is seen from the origin.
struct AngleRange {
    double lo, hi;
};
AngleRange sphereAngles(const glm::dvec3& center, double radius, const glm::dvec3& axis) {
    const double dist = glm::length(center);
    if (dist <= radius)
        return {0.0, kPi};
    const double theta = angleBetween(axis, center);
    const double delta = std::asin(std::min(1.0, radius / dist));
    return {std::max(0.0, theta - delta), std::min(kPi, theta + delta)};
}

enum class BoxSide { kOutside, kInside, kStraddles };

BoxSide boxAgainst(const glm::vec3& mn, const glm::vec3& mx, const Plane* planes, int count) {
    bool all_inside = true;
    for (int i = 0; i < count; ++i) {
        const Plane& p = planes[i];
        // The box corner farthest along the normal, and the nearest one.
        const glm::dvec3 far_c(p.n.x >= 0 ? mx.x : mn.x, p.n.y >= 0 ? mx.y : mn.y,
                               p.n.z >= 0 ? mx.z : mn.z);
        const glm::dvec3 near_c(p.n.x >= 0 ? mn.x : mx.x, p.n.y >= 0 ? mn.y : mx.y,
                                p.n.z >= 0 ? mn.z : mx.z);
        // A small slack keeps rounding in the transformed planes conservative.
        const double slack = 1e-9 * (1.0 + std::fabs(p.d));
        if (p.distance(far_c) < -slack)
            return BoxSide::kOutside;
        if (p.distance(near_c) < slack)
            all_inside = false;
    }
    return all_inside ? BoxSide::kInside : BoxSide::kStraddles;
}

}  // namespace

EyeView EyeView::symmetric(const glm::dvec3& position_m, const glm::dquat& orientation,
                           double fov_h_deg, double fov_v_deg, double near_m, double far_m) {
    EyeView v;
    v.position_m = position_m;
    v.orientation = orientation;
    v.tan_left = v.tan_right = std::tan(0.5 * fov_h_deg * kRadPerDeg);
    v.tan_down = v.tan_up = std::tan(0.5 * fov_v_deg * kRadPerDeg);
    v.near_m = near_m;
    v.far_m = far_m;
    return v;
}

TriangleBvh::TriangleBvh(const Scene& scene) {
    std::vector<glm::vec3> positions(scene.vertices.size());
    for (size_t i = 0; i < positions.size(); ++i)
        positions[i] = scene.vertices[i].position;
    build(positions, scene.indices);
}

TriangleBvh::TriangleBvh(const std::vector<glm::vec3>& positions,
                         const std::vector<uint32_t>& indices) {
    build(positions, indices);
}

void TriangleBvh::build(const std::vector<glm::vec3>& positions,
                        const std::vector<uint32_t>& indices) {
    QVR_CHECK_MSG(indices.size() % 3 == 0, "indices must be whole triangles");
    m_tri_count = indices.size() / 3;
    for (uint32_t i : indices)
        QVR_CHECK_MSG(i < positions.size(), "index past the vertex buffer");
    for (const auto& p : positions)
        QVR_CHECK_MSG(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z),
                      "non-finite vertex position");
    QVR_CHECK_MSG(m_tri_count < (1u << 31), "too many triangles for one BVH");
    std::vector<uint32_t> order(m_tri_count);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<glm::vec3> centroid(m_tri_count);
    for (size_t t = 0; t < m_tri_count; ++t)
        centroid[t] = (positions[indices[3 * t]] + positions[indices[3 * t + 1]] +
                       positions[indices[3 * t + 2]]) /
                      3.0f;
    m_nodes.clear();
    m_nodes.reserve(2 * (m_tri_count / kLeafTriangles + 1));
    m_nodes.push_back(Node{});
    if (m_tri_count == 0) {
        m_nodes[0] = Node{glm::vec3(0), glm::vec3(0), 0, 0, 0};
        return;
    }
    // Iterative top-down build: split each node at the median centroid of its longest centroid
    // axis until it holds kLeafTriangles or fewer.
    struct Job {
        uint32_t node, begin, end;
    };
    std::vector<Job> stack = {{0, 0, static_cast<uint32_t>(m_tri_count)}};
    while (!stack.empty()) {
        const Job job = stack.back();
        stack.pop_back();
        glm::vec3 mn(1e30f), mx(-1e30f), cmn(1e30f), cmx(-1e30f);
        for (uint32_t i = job.begin; i < job.end; ++i) {
            const uint32_t t = order[i];
            for (int k = 0; k < 3; ++k) {
                mn = glm::min(mn, positions[indices[3 * t + static_cast<uint32_t>(k)]]);
                mx = glm::max(mx, positions[indices[3 * t + static_cast<uint32_t>(k)]]);
            }
            cmn = glm::min(cmn, centroid[t]);
            cmx = glm::max(cmx, centroid[t]);
        }
        Node& node = m_nodes[job.node];
        node.min = mn;
        node.max = mx;
        node.begin = job.begin;
        node.end = job.end;
        node.left = 0;
        const uint32_t n = job.end - job.begin;
        const glm::vec3 ext = cmx - cmn;
        if (n <= kLeafTriangles || (ext.x <= 0 && ext.y <= 0 && ext.z <= 0))
            continue;
        const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
        const uint32_t mid = job.begin + n / 2;
        std::nth_element(
            order.begin() + job.begin, order.begin() + mid, order.begin() + job.end,
            [&](uint32_t a, uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
        const uint32_t left = static_cast<uint32_t>(m_nodes.size());
        node.left = left;
        m_nodes.push_back(Node{});
        m_nodes.push_back(Node{});
        stack.push_back({left, job.begin, mid});
        stack.push_back({left + 1, mid, job.end});
    }
    m_tri.resize(3 * m_tri_count);
    for (size_t i = 0; i < m_tri_count; ++i) {
        for (size_t k = 0; k < 3; ++k)
            m_tri[3 * i + k] = positions[indices[3 * order[i] + k]];
    }
}

uint64_t TriangleBvh::countTrianglesInCone(const ViewCone& cone) const {
    const ConeFrame c = coneFrame(cone);
    if (m_tri_count == 0)
        return 0;
    const Plane slab[2] = {Plane{c.axis, -c.near_m - glm::dot(c.axis, c.apex)},
                           Plane{-c.axis, c.far_m + glm::dot(c.axis, c.apex)}};
    uint64_t count = 0;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = m_nodes[stack[--top]];
        const BoxSide side = boxAgainst(node.min, node.max, slab, 2);
        if (side == BoxSide::kOutside)
            continue;
        const glm::dvec3 center = 0.5 * (glm::dvec3(node.min) + glm::dvec3(node.max));
        const double radius = 0.5 * glm::length(glm::dvec3(node.max) - glm::dvec3(node.min));
        const AngleRange r = sphereAngles(center - c.apex, radius, c.axis);
        if (r.lo > c.half_angle + kAngleMargin)
            continue;
        if (side == BoxSide::kInside && r.hi < c.half_angle - kAngleMargin &&
            glm::length(center - c.apex) > radius * (1.0 + 1e-9) + 1e-9) {
            // The whole subtree lies inside the cone: count it without visiting.
            count += node.end - node.begin;
            continue;
        }
        if (node.left == 0) {
            for (uint32_t i = node.begin; i < node.end; ++i)
                count += triangleInCone(&m_tri[3 * static_cast<size_t>(i)], c) ? 1 : 0;
        } else {
            QVR_CHECK(top + 2 <= 64);
            stack[top++] = node.left;
            stack[top++] = node.left + 1;
        }
    }
    return count;
}

uint64_t TriangleBvh::countTrianglesInConeBruteForce(const ViewCone& cone) const {
    const ConeFrame c = coneFrame(cone);
    uint64_t count = 0;
    for (size_t t = 0; t < m_tri_count; ++t)
        count += triangleInCone(&m_tri[3 * t], c) ? 1 : 0;
    return count;
}

uint64_t TriangleBvh::countTrianglesInFrustum(const EyeView& view) const {
    const std::vector<uint64_t> rings = trianglesPerRing(view, glm::dvec3(0, 0, -1), 180.0, 1);
    return rings[0];
}

uint64_t TriangleBvh::countTrianglesInFrustumBruteForce(const EyeView& view) const {
    checkView(view);
    const auto eye = eyeFrustum(view);
    uint64_t count = 0;
    for (size_t t = 0; t < m_tri_count; ++t)
        count += clipToView(&m_tri[3 * t], view, eye).count > 0 ? 1 : 0;
    return count;
}

std::vector<uint64_t> TriangleBvh::trianglesPerRing(const EyeView& view,
                                                    const glm::dvec3& gaze_dir_eye, double ring_deg,
                                                    int rings) const {
    checkView(view);
    QVR_CHECK_MSG(rings >= 1 && ring_deg > 0.0, "need rings ≥ 1 and ring_deg > 0");
    QVR_CHECK_MSG(glm::length(gaze_dir_eye) > 0.0, "gaze direction is zero");
    std::vector<uint64_t> hist(static_cast<size_t>(rings), 0);
    if (m_tri_count == 0)
        return hist;
    const auto eye = eyeFrustum(view);
    const auto world = worldFrustum(view);
    const glm::dvec3 g_eye = glm::normalize(gaze_dir_eye);
    const glm::dvec3 g_world = view.orientation * g_eye;
    const double ring_rad = ring_deg * kRadPerDeg;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = m_nodes[stack[--top]];
        const BoxSide side = boxAgainst(node.min, node.max, world.data(), 6);
        if (side == BoxSide::kOutside)
            continue;
        if (side == BoxSide::kInside) {
            // Entirely inside the frustum: if its bounding sphere's angular range lies within
            // one ring, every triangle below lands in that ring.
            const glm::dvec3 center = 0.5 * (glm::dvec3(node.min) + glm::dvec3(node.max));
            const double radius = 0.5 * glm::length(glm::dvec3(node.max) - glm::dvec3(node.min));
            const AngleRange r = sphereAngles(center - view.position_m, radius, g_world);
            const int lo = ringOf(std::max(0.0, r.lo - kAngleMargin), ring_rad, rings);
            const int hi = ringOf(r.hi + kAngleMargin, ring_rad, rings);
            if (lo == hi && glm::length(center - view.position_m) > radius) {
                hist[static_cast<size_t>(lo)] += node.end - node.begin;
                continue;
            }
        }
        if (node.left == 0) {
            for (uint32_t i = node.begin; i < node.end; ++i) {
                const Polygon poly = clipToView(&m_tri[3 * static_cast<size_t>(i)], view, eye);
                if (poly.count == 0)
                    continue;
                const int ring = rings == 1 ? 0 : ringOf(minAngle(poly, g_eye), ring_rad, rings);
                ++hist[static_cast<size_t>(ring)];
            }
        } else {
            QVR_CHECK(top + 2 <= 64);
            stack[top++] = node.left;
            stack[top++] = node.left + 1;
        }
    }
    return hist;
}

std::vector<uint64_t> TriangleBvh::trianglesPerRingBruteForce(const EyeView& view,
                                                              const glm::dvec3& gaze_dir_eye,
                                                              double ring_deg, int rings) const {
    checkView(view);
    QVR_CHECK_MSG(rings >= 1 && ring_deg > 0.0, "need rings ≥ 1 and ring_deg > 0");
    std::vector<uint64_t> hist(static_cast<size_t>(rings), 0);
    const auto eye = eyeFrustum(view);
    const glm::dvec3 g_eye = glm::normalize(gaze_dir_eye);
    const double ring_rad = ring_deg * kRadPerDeg;
    for (size_t t = 0; t < m_tri_count; ++t) {
        const Polygon poly = clipToView(&m_tri[3 * t], view, eye);
        if (poly.count == 0)
            continue;
        ++hist[static_cast<size_t>(rings == 1 ? 0
                                              : ringOf(minAngle(poly, g_eye), ring_rad, rings))];
    }
    return hist;
}

}  // namespace qvr
