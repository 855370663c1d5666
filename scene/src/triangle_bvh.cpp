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
constexpr int kSahBins = 16;
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

// The cosine of the smallest angle between the unit direction g and the directions from the
// origin to points of the convex planar polygon, all of which lie strictly on one side of a
// plane through the origin (in front of the eye) or at the origin (cosine 1). Cosines rather
// than angles: no inverse trigonometry on the per-triangle path.
double maxCos(const Polygon& poly, const glm::dvec3& g) {
    const int n = poly.count;
    for (int i = 0; i < n; ++i) {
        if (glm::dot(poly.v[static_cast<size_t>(i)], poly.v[static_cast<size_t>(i)]) < 1e-24)
            return 1.0;
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
                    return 1.0;
            }
        }
    }
    // Otherwise the nearest direction lies on an edge: the great-circle arc between its ends,
    // either at an end or where g's projection into the arc's plane falls within the arc
    // (there the cosine is the projection's length).
    double best = -1.0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3& a = poly.v[static_cast<size_t>(i)];
        const glm::dvec3& b = poly.v[static_cast<size_t>((i + 1) % n)];
        best = std::max(best, glm::dot(g, a) / glm::length(a));
        const glm::dvec3 c = glm::cross(a, b);
        const double cl = glm::length(c);
        if (cl < 1e-300)
            continue;
        const glm::dvec3 cn = c / cl;
        const glm::dvec3 gp = g - glm::dot(g, cn) * cn;  // g projected into the arc's plane
        if (glm::dot(glm::cross(a, gp), cn) >= 0.0 && glm::dot(glm::cross(gp, b), cn) >= 0.0 &&
            glm::dot(gp, a + b) > 0.0)
            best = std::max(best, glm::length(gp));
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
// Rings are classified by cosines against precomputed boundaries, and bounding spheres' angular
// extents are computed without trigonometric calls: both run for every node a query visits.
// Node-level decisions keep kCosMargin away from a boundary so that rounding can never make
// them disagree with the exact per-triangle test.
constexpr double kCosMargin = 1e-9;

// Angular extent about a unit axis of a sphere seen from the origin, as cosines: every point
// of the sphere lies at an angle whose cosine is within [cos_hi, cos_lo]. Not valid when the
// sphere contains the origin.
struct CosRange {
    double cos_lo = 1.0;
    double cos_hi = -1.0;
    bool valid = false;
};

CosRange sphereCosRange(const glm::dvec3& center, double radius, const glm::dvec3& axis) {
    CosRange r;
    const double d2 = glm::dot(center, center);
    if (d2 <= radius * radius)
        return r;
    const double d = std::sqrt(d2);
    const double c = glm::dot(axis, center) / d;                 // cos θ of the centre
    const double s = glm::length(glm::cross(axis, center)) / d;  // sin θ
    const double sd = radius / d;                                // sin δ, the half-extent
    const double cd = std::sqrt(std::max(0.0, 1.0 - sd * sd));
    r.valid = true;
    // θ − δ ∈ [−π/2, π]: it is ≤ 0 exactly when its sine is.
    if (s * cd - c * sd > 0.0)
        r.cos_lo = c * cd + s * sd;
    // θ + δ ∈ [0, 3π/2]: it stays ≤ π exactly when its sine is ≥ 0.
    if (s * cd + c * sd >= 0.0)
        r.cos_hi = c * cd - s * sd;
    return r;
}

// Ring k covers angles [k·ring, (k + 1)·ring); the last ring is open-ended.
class RingBounds {
public:
    RingBounds(double ring_rad, int rings) {
        for (int j = 1; j < rings && j * ring_rad < kPi; ++j)
            m_cos.push_back(std::cos(j * ring_rad));
    }
    // The ring of an angle given by its cosine: the number of boundaries it has reached.
    int ofCos(double c) const {
        int k = 0;
        const int n = static_cast<int>(m_cos.size());
        while (k < n && m_cos[static_cast<size_t>(k)] >= c)
            ++k;
        return k;
    }
    // The ring all of a range lies in, or −1 when it may span two.
    int ofRange(const CosRange& r) const {
        if (!r.valid)
            return -1;
        const int lo = ofCos(std::min(1.0, r.cos_lo + kCosMargin));
        const int hi = ofCos(r.cos_hi - kCosMargin);
        return lo == hi ? lo : -1;
    }

private:
    std::vector<double> m_cos;  // cos(j·ring) for the boundaries j = 1 … below 180°
};

// Bounding sphere of three points (centroid-centred: looser than minimal, cheaper).
void triangleSphere(const glm::dvec3* v, glm::dvec3& center, double& radius) {
    center = (v[0] + v[1] + v[2]) / 3.0;
    radius = std::sqrt(std::max({glm::dot(v[0] - center, v[0] - center),
                                 glm::dot(v[1] - center, v[1] - center),
                                 glm::dot(v[2] - center, v[2] - center)})) *
             (1.0 + 1e-12);
}

// A frustum query prepared once: eye-space planes, the world-to-eye rotation, the gaze.
class ViewQuery {
public:
    ViewQuery(const EyeView& view, const glm::dvec3& gaze_dir_eye, double ring_deg, int rings)
        : m_view(view),
          m_eye(eyeFrustum(view)),
          m_world_to_eye(glm::mat3_cast(glm::conjugate(view.orientation))),
          m_gaze(glm::normalize(gaze_dir_eye)),
          m_rings(ring_deg * kRadPerDeg, rings),
          m_ring_count(rings) {}

    const RingBounds& rings() const { return m_rings; }
    int ringCount() const { return m_ring_count; }

    // The ring of a world-space triangle, −1 when it misses the frustum. exact_only skips the
    // shortcuts (no clipping when all vertices are inside, ring from the bounding sphere when
    // unambiguous) and applies the definition directly, for the brute-force twin.
    int classify(const glm::vec3* tri, bool exact_only) const {
        Polygon poly;
        poly.count = 3;
        for (size_t k = 0; k < 3; ++k)
            poly.v[k] = m_world_to_eye * (glm::dvec3(tri[k]) - m_view.position_m);
        bool inside = !exact_only;
        for (const Plane& p : m_eye) {
            if (!inside)
                break;
            for (size_t k = 0; k < 3; ++k)
                inside = inside && p.distance(poly.v[k]) >= 0.0;
        }
        if (!inside) {
            for (const Plane& p : m_eye)
                clip(poly, p);
            if (poly.count == 0)
                return -1;
        }
        if (m_ring_count == 1)
            return 0;
        if (inside) {
            glm::dvec3 center;
            double radius;
            triangleSphere(poly.v.data(), center, radius);
            const int ring = m_rings.ofRange(sphereCosRange(center, radius, m_gaze));
            if (ring >= 0)
                return ring;
        }
        return m_rings.ofCos(maxCos(poly, m_gaze));
    }

private:
    EyeView m_view;
    std::array<Plane, 6> m_eye;
    glm::dmat3 m_world_to_eye;
    glm::dvec3 m_gaze;
    RingBounds m_rings;
    int m_ring_count;
};

// A cone query prepared once.
class ConeQuery {
public:
    explicit ConeQuery(const ViewCone& c) {
        QVR_CHECK_MSG(c.half_angle_deg > 0.0 && c.half_angle_deg < 90.0,
                      "cone half-angle must be in (0, 90) degrees");
        QVR_CHECK_MSG(glm::length(c.direction) > 0.0, "cone direction is zero");
        QVR_CHECK_MSG(c.near_m >= 0.0 && c.far_m > c.near_m, "cone needs 0 ≤ near < far");
        apex = c.apex_m;
        axis = glm::normalize(c.direction);
        half_angle = c.half_angle_deg * kRadPerDeg;
        cos_half = std::cos(half_angle);
        near_m = c.near_m;
        far_m = c.far_m;
    }

    bool contains(const glm::vec3* tri, bool exact_only) const {
        Polygon poly;
        poly.count = 3;
        bool inside = !exact_only;
        for (size_t k = 0; k < 3; ++k) {
            poly.v[k] = glm::dvec3(tri[k]) - apex;
            const double along = glm::dot(poly.v[k], axis);
            inside = inside && along >= near_m && along <= far_m;
        }
        if (inside) {
            glm::dvec3 center;
            double radius;
            triangleSphere(poly.v.data(), center, radius);
            const CosRange r = sphereCosRange(center, radius, axis);
            if (r.valid && r.cos_lo < cos_half - kCosMargin)
                return false;
            if (r.valid && r.cos_hi > cos_half + kCosMargin)
                return true;
        } else {
            clip(poly, Plane{axis, -near_m});
            clip(poly, Plane{-axis, far_m});
            if (poly.count == 0)
                return false;
        }
        return maxCos(poly, axis) >= cos_half;
    }

    glm::dvec3 apex, axis;
    double half_angle, cos_half, near_m, far_m;
};

enum class BoxSide { kOutside, kInside, kStraddles };

// Tests a box against the planes whose bit is set in *mask and clears the bits of planes the
// box lies entirely inside, so a subtree never re-tests a plane its ancestor already cleared.
BoxSide boxAgainst(const glm::vec3& mn, const glm::vec3& mx, const Plane* planes, int count,
                   uint32_t* mask) {
    for (int i = 0; i < count; ++i) {
        if ((*mask & (1u << i)) == 0)
            continue;
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
        if (p.distance(near_c) >= slack)
            *mask &= ~(1u << i);
    }
    return *mask == 0 ? BoxSide::kInside : BoxSide::kStraddles;
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
        // Binned surface-area heuristic along the longest centroid axis: tight boxes keep
        // queries from descending into nodes that only brush a ring or plane.
        struct Bin {
            glm::vec3 mn{1e30f}, mx{-1e30f};
            uint32_t count = 0;
        };
        std::array<Bin, kSahBins> bins;
        const float lo = cmn[axis];
        const float scale = static_cast<float>(kSahBins) / ext[axis];
        auto binOf = [&](uint32_t t) {
            return std::min(kSahBins - 1, static_cast<int>((centroid[t][axis] - lo) * scale));
        };
        for (uint32_t i = job.begin; i < job.end; ++i) {
            const uint32_t t = order[i];
            Bin& b = bins[static_cast<size_t>(binOf(t))];
            ++b.count;
            for (int k = 0; k < 3; ++k) {
                b.mn = glm::min(b.mn, positions[indices[3 * t + static_cast<uint32_t>(k)]]);
                b.mx = glm::max(b.mx, positions[indices[3 * t + static_cast<uint32_t>(k)]]);
            }
        }
        auto area = [](const glm::vec3& a, const glm::vec3& b) {
            const glm::vec3 e = glm::max(b - a, glm::vec3(0));
            return e.x * e.y + e.y * e.z + e.z * e.x;
        };
        std::array<float, kSahBins> left_cost{};
        glm::vec3 amn(1e30f), amx(-1e30f);
        uint32_t acount = 0;
        for (int i = 0; i < kSahBins - 1; ++i) {
            amn = glm::min(amn, bins[static_cast<size_t>(i)].mn);
            amx = glm::max(amx, bins[static_cast<size_t>(i)].mx);
            acount += bins[static_cast<size_t>(i)].count;
            left_cost[static_cast<size_t>(i)] =
                acount == 0 ? 0.0f : area(amn, amx) * static_cast<float>(acount);
        }
        int best = -1;
        float best_cost = 1e38f;
        amn = glm::vec3(1e30f);
        amx = glm::vec3(-1e30f);
        acount = 0;
        for (int i = kSahBins - 1; i >= 1; --i) {
            amn = glm::min(amn, bins[static_cast<size_t>(i)].mn);
            amx = glm::max(amx, bins[static_cast<size_t>(i)].mx);
            acount += bins[static_cast<size_t>(i)].count;
            const uint32_t left_count = n - acount;
            if (acount == 0 || left_count == 0)
                continue;
            const float cost =
                left_cost[static_cast<size_t>(i - 1)] + area(amn, amx) * static_cast<float>(acount);
            if (cost < best_cost) {
                best_cost = cost;
                best = i;
            }
        }
        uint32_t mid = job.begin + n / 2;
        if (best > 0) {
            mid = static_cast<uint32_t>(
                std::partition(order.begin() + job.begin, order.begin() + job.end,
                               [&](uint32_t t) { return binOf(t) < best; }) -
                order.begin());
        }
        if (best <= 0 || mid == job.begin || mid == job.end) {
            // Every centroid in one bin: fall back to the median.
            mid = job.begin + n / 2;
            std::nth_element(
                order.begin() + job.begin, order.begin() + mid, order.begin() + job.end,
                [&](uint32_t a, uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
        }
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

namespace {

// Node bounding sphere from its box.
void nodeSphere(const glm::vec3& mn, const glm::vec3& mx, glm::dvec3& center, double& radius) {
    center = 0.5 * (glm::dvec3(mn) + glm::dvec3(mx));
    radius = 0.5 * glm::length(glm::dvec3(mx) - glm::dvec3(mn)) * (1.0 + 1e-12);
}

// Depth-first over the nodes whose boxes are not outside the planes. `whole(node, side)` ends a
// node's walk when it returns true (the node is outside the query or counted whole); otherwise
// the walk goes on into its children, or at a leaf calls `leaf(node)` to test its triangles.
template <typename Nodes, typename Whole, typename Leaf>
void walkNodes(const Nodes& nodes, const Plane* planes, int plane_count, BvhQueryStats& st,
               Whole whole, Leaf leaf) {
    // (node, planes still to test) pairs.
    std::pair<uint32_t, uint32_t> stack[64];
    int top = 0;
    stack[top++] = {0u, (1u << plane_count) - 1};
    while (top > 0) {
        auto [node_index, mask] = stack[--top];
        const auto& node = nodes[node_index];
        ++st.nodes_visited;
        const BoxSide side = boxAgainst(node.min, node.max, planes, plane_count, &mask);
        if (side == BoxSide::kOutside || whole(node, side))
            continue;
        if (node.left == 0) {
            st.triangles_tested += node.end - node.begin;
            leaf(node);
        } else {
            QVR_CHECK(top + 2 <= 64);
            stack[top++] = {node.left, mask};
            stack[top++] = {node.left + 1, mask};
        }
    }
}

}  // namespace

uint64_t TriangleBvh::countTrianglesInCone(const ViewCone& cone, BvhQueryStats* stats) const {
    BvhQueryStats local;
    BvhQueryStats& st = stats != nullptr ? *stats : local;
    const ConeQuery q(cone);
    if (m_tri_count == 0)
        return 0;
    const Plane slab[2] = {Plane{q.axis, -q.near_m - glm::dot(q.axis, q.apex)},
                           Plane{-q.axis, q.far_m + glm::dot(q.axis, q.apex)}};
    uint64_t count = 0;
    const auto whole = [&](const Node& node, BoxSide side) {
        glm::dvec3 center;
        double radius;
        nodeSphere(node.min, node.max, center, radius);
        const CosRange r = sphereCosRange(center - q.apex, radius, q.axis);
        if (r.valid && r.cos_lo < q.cos_half - kCosMargin)
            return true;  // entirely outside the cone
        if (side == BoxSide::kInside && r.valid && r.cos_hi > q.cos_half + kCosMargin) {
            // The whole subtree lies inside the cone: count it without visiting.
            count += node.end - node.begin;
            ++st.nodes_accepted_whole;
            return true;
        }
        return false;
    };
    walkNodes(m_nodes, slab, 2, st, whole, [&](const Node& node) {
        for (uint32_t i = node.begin; i < node.end; ++i)
            count += q.contains(&m_tri[3 * static_cast<size_t>(i)], false) ? 1 : 0;
    });
    return count;
}

uint64_t TriangleBvh::countTrianglesInConeBruteForce(const ViewCone& cone) const {
    const ConeQuery q(cone);
    uint64_t count = 0;
    for (size_t t = 0; t < m_tri_count; ++t)
        count += q.contains(&m_tri[3 * t], true) ? 1 : 0;
    return count;
}

uint64_t TriangleBvh::countTrianglesInFrustum(const EyeView& view, BvhQueryStats* stats) const {
    return trianglesPerRing(view, glm::dvec3(0, 0, -1), 180.0, 1, stats)[0];
}

uint64_t TriangleBvh::countTrianglesInFrustumBruteForce(const EyeView& view) const {
    return trianglesPerRingBruteForce(view, glm::dvec3(0, 0, -1), 180.0, 1)[0];
}

std::vector<uint64_t> TriangleBvh::trianglesPerRing(const EyeView& view,
                                                    const glm::dvec3& gaze_dir_eye, double ring_deg,
                                                    int rings, BvhQueryStats* stats) const {
    BvhQueryStats local;
    BvhQueryStats& st = stats != nullptr ? *stats : local;
    checkView(view);
    QVR_CHECK_MSG(rings >= 1 && ring_deg > 0.0, "need rings ≥ 1 and ring_deg > 0");
    QVR_CHECK_MSG(glm::length(gaze_dir_eye) > 0.0, "gaze direction is zero");
    std::vector<uint64_t> hist(static_cast<size_t>(rings), 0);
    if (m_tri_count == 0)
        return hist;
    const ViewQuery q(view, gaze_dir_eye, ring_deg, rings);
    const auto world = worldFrustum(view);
    const glm::dvec3 g_world = view.orientation * glm::normalize(gaze_dir_eye);
    const auto whole = [&](const Node& node, BoxSide side) {
        if (side != BoxSide::kInside)
            return false;
        // Entirely inside the frustum: if its bounding sphere's angular range lies within one
        // ring, every triangle below lands in that ring.
        int ring = 0;
        if (rings > 1) {
            glm::dvec3 center;
            double radius;
            nodeSphere(node.min, node.max, center, radius);
            ring = q.rings().ofRange(sphereCosRange(center - view.position_m, radius, g_world));
        }
        if (ring < 0)
            return false;
        hist[static_cast<size_t>(ring)] += node.end - node.begin;
        ++st.nodes_accepted_whole;
        return true;
    };
    walkNodes(m_nodes, world.data(), 6, st, whole, [&](const Node& node) {
        for (uint32_t i = node.begin; i < node.end; ++i) {
            const int ring = q.classify(&m_tri[3 * static_cast<size_t>(i)], false);
            if (ring >= 0)
                ++hist[static_cast<size_t>(ring)];
        }
    });
    return hist;
}

uint64_t TriangleBvh::countTrianglesByOutcodes(const EyeView& view) const {
    checkView(view);
    const auto eye = eyeFrustum(view);
    const glm::dmat3 world_to_eye = glm::mat3_cast(glm::conjugate(view.orientation));
    uint64_t count = 0;
    for (size_t t = 0; t < m_tri_count; ++t) {
        uint32_t outside_all = 0x3f;  // planes every vertex so far lies outside of
        for (size_t k = 0; k < 3; ++k) {
            const glm::dvec3 p = world_to_eye * (glm::dvec3(m_tri[3 * t + k]) - view.position_m);
            uint32_t outside = 0;
            for (size_t i = 0; i < eye.size(); ++i)
                outside |= eye[i].distance(p) < 0.0 ? (1u << i) : 0u;
            outside_all &= outside;
        }
        count += outside_all == 0 ? 1 : 0;
    }
    return count;
}

std::vector<uint64_t> TriangleBvh::trianglesPerRingBruteForce(const EyeView& view,
                                                              const glm::dvec3& gaze_dir_eye,
                                                              double ring_deg, int rings) const {
    checkView(view);
    QVR_CHECK_MSG(rings >= 1 && ring_deg > 0.0, "need rings ≥ 1 and ring_deg > 0");
    QVR_CHECK_MSG(glm::length(gaze_dir_eye) > 0.0, "gaze direction is zero");
    std::vector<uint64_t> hist(static_cast<size_t>(rings), 0);
    const ViewQuery q(view, gaze_dir_eye, ring_deg, rings);
    for (size_t t = 0; t < m_tri_count; ++t) {
        const int ring = q.classify(&m_tri[3 * t], true);
        if (ring >= 0)
            ++hist[static_cast<size_t>(ring)];
    }
    return hist;
}

}  // namespace qvr
