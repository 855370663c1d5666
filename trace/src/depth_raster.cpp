// CPU z-buffer for the workload recorder: near-plane clipping in clip space, edge functions at
// pixel centres, 1/w interpolated affinely in screen space (it is, under perspective), early
// depth test in draw order for the overdraw count.
#include "qvr/trace/depth_raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include <glm/vec4.hpp>

#include "qvr/core/check.h"

namespace qvr {

namespace {

struct ScreenVertex {
    double x, y;   // raster pixels, row 0 at the top
    double inv_w;  // 1 / eye depth
};

uint32_t outcode(const glm::dvec4& c) {
    uint32_t code = 0;
    code |= (c.x < -c.w) ? 1u : 0u;
    code |= (c.x > c.w) ? 2u : 0u;
    code |= (c.y < -c.w) ? 4u : 0u;
    code |= (c.y > c.w) ? 8u : 0u;
    code |= (c.z < -c.w) ? 16u : 0u;
    code |= (c.z > c.w) ? 32u : 0u;
    return code;
}

struct RasterTarget {
    int width;
    int height;
    std::vector<float>& inv_depth;
    std::vector<int32_t>& object;
    std::vector<uint16_t>& shaded;
};

void drawTriangle(const ScreenVertex& a, const ScreenVertex& b, const ScreenVertex& c,
                  int32_t object_id, RasterTarget& t) {
    const double area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (!(std::fabs(area) > 1e-12))
        return;
    const double sign = area > 0 ? 1.0 : -1.0;
    const double inv_area = 1.0 / std::fabs(area);
    // Pixel centres i + 0.5 inside the bounding box, clamped before converting to int so a
    // vertex far outside the view cannot overflow.
    auto lo = [](double v, int n) {
        return static_cast<int>(std::clamp(std::ceil(v - 0.5), 0.0, static_cast<double>(n)));
    };
    auto hi = [](double v, int n) {
        return static_cast<int>(std::clamp(std::floor(v - 0.5), -1.0, static_cast<double>(n - 1)));
    };
    const int x0 = lo(std::min({a.x, b.x, c.x}), t.width);
    const int x1 = hi(std::max({a.x, b.x, c.x}), t.width);
    const int y0 = lo(std::min({a.y, b.y, c.y}), t.height);
    const int y1 = hi(std::max({a.y, b.y, c.y}), t.height);
    if (x0 > x1 || y0 > y1)
        return;
    // Edge function e_k(p) for the edge opposite vertex k, oriented so inside is ≥ 0:
    // e(p) = A·px + B·py + C.
    struct Edge {
        double A, B, C;
    };
    auto edge = [sign](const ScreenVertex& p, const ScreenVertex& q) {
        return Edge{sign * (p.y - q.y), sign * (q.x - p.x), sign * (p.x * q.y - p.y * q.x)};
    };
    const std::array<Edge, 3> e = {edge(b, c), edge(c, a), edge(a, b)};
    for (int y = y0; y <= y1; ++y) {
        const double py = y + 0.5;
        const double px0 = x0 + 0.5;
        double w0 = e[0].A * px0 + e[0].B * py + e[0].C;
        double w1 = e[1].A * px0 + e[1].B * py + e[1].C;
        double w2 = e[2].A * px0 + e[2].B * py + e[2].C;
        const size_t row = static_cast<size_t>(y) * static_cast<size_t>(t.width);
        for (int x = x0; x <= x1; ++x, w0 += e[0].A, w1 += e[1].A, w2 += e[2].A) {
            if (w0 < 0 || w1 < 0 || w2 < 0)
                continue;
            const double inv = (w0 * a.inv_w + w1 * b.inv_w + w2 * c.inv_w) * inv_area;
            const size_t p = row + static_cast<size_t>(x);
            if (inv > t.inv_depth[p]) {
                t.inv_depth[p] = static_cast<float>(inv);
                t.object[p] = object_id;
                if (t.shaded[p] != UINT16_MAX)
                    ++t.shaded[p];
            }
        }
    }
}

}  // namespace

double distanceToBox(const glm::vec3& p, const Aabb& box) {
    const glm::vec3 d = glm::max(glm::max(box.min - p, p - box.max), glm::vec3(0.0f));
    return std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y +
                     static_cast<double>(d.z) * d.z);
}

DepthRasterizer::DepthRasterizer(const Scene& scene, double cell_m) : m_scene(scene) {
    QVR_CHECK(cell_m > 0.0);
    m_tri_object.assign(scene.triangleCount(), -1);
    // Key: batch and integer cell of the centroid, packed into 64 bits (21 bits a coordinate:
    // ±1 million cells, far more than any level at 1 m cells).
    std::unordered_map<uint64_t, int32_t> ids;
    for (size_t b = 0; b < scene.batches.size(); ++b) {
        const SceneBatch& batch = scene.batches[b];
        ids.clear();
        for (uint32_t k = batch.first_index; k + 2 < batch.first_index + batch.index_count;
             k += 3) {
            const glm::vec3 c = (scene.vertices[scene.indices[k]].position +
                                 scene.vertices[scene.indices[k + 1]].position +
                                 scene.vertices[scene.indices[k + 2]].position) /
                                3.0f;
            auto cell = [cell_m](float v) {
                const double i = std::clamp(std::floor(v / cell_m), -1048575.0, 1048575.0);
                return static_cast<uint64_t>(static_cast<int64_t>(i) + 1048576) & 0x1FFFFFu;
            };
            const uint64_t key = cell(c.x) | (cell(c.y) << 21) | (cell(c.z) << 42);
            auto [it, inserted] =
                ids.try_emplace(key, static_cast<int32_t>(m_object_bounds.size()));
            if (inserted) {
                m_object_bounds.emplace_back();
                m_object_batch.push_back(static_cast<int>(b));
            }
            Aabb& box = m_object_bounds[static_cast<size_t>(it->second)];
            for (int v = 0; v < 3; ++v)
                box.extend(scene.vertices[scene.indices[k + static_cast<uint32_t>(v)]].position);
            m_tri_object[k / 3] = it->second;
        }
    }
}

void DepthRasterizer::rasterize(const glm::mat4& view, const glm::mat4& projection, int full_width,
                                int full_height, int scale, DepthRaster& out) const {
    QVR_CHECK(full_width > 0 && full_height > 0 && scale >= 1);
    out.scale = scale;
    out.width = (full_width + scale - 1) / scale;
    out.height = (full_height + scale - 1) / scale;
    const size_t n = static_cast<size_t>(out.width) * static_cast<size_t>(out.height);
    std::vector<float> inv_depth(n, 0.0f);
    out.object.assign(n, -1);
    out.shaded.assign(n, 0);
    out.object_triangles.assign(m_object_bounds.size(), 0);
    out.object_pixels.assign(m_object_bounds.size(), 0);

    const glm::dmat4 vp = glm::dmat4(projection) * glm::dmat4(view);
    std::vector<glm::dvec4> clip(m_scene.vertices.size());
    for (size_t i = 0; i < clip.size(); ++i)
        clip[i] = vp * glm::dvec4(glm::dvec3(m_scene.vertices[i].position), 1.0);

    // Raster pixels per NDC unit: the full-resolution viewport divided by the scale.
    const double sx = 0.5 * full_width / scale;
    const double sy = 0.5 * full_height / scale;
    auto toScreen = [sx, sy](const glm::dvec4& c) {
        const double iw = 1.0 / c.w;
        return ScreenVertex{(c.x * iw + 1.0) * sx, (1.0 - c.y * iw) * sy, iw};
    };
    RasterTarget target{out.width, out.height, inv_depth, out.object, out.shaded};
    for (const SceneBatch& batch : m_scene.batches) {
        for (uint32_t k = batch.first_index; k + 2 < batch.first_index + batch.index_count;
             k += 3) {
            const std::array<glm::dvec4, 3> v = {clip[m_scene.indices[k]],
                                                 clip[m_scene.indices[k + 1]],
                                                 clip[m_scene.indices[k + 2]]};
            const uint32_t c0 = outcode(v[0]), c1 = outcode(v[1]), c2 = outcode(v[2]);
            if ((c0 & c1 & c2) != 0)
                continue;
            const int32_t id = m_tri_object[k / 3];
            ++out.object_triangles[static_cast<size_t>(id)];
            if (((c0 | c1 | c2) & 16u) == 0) {
                drawTriangle(toScreen(v[0]), toScreen(v[1]), toScreen(v[2]), id, target);
                continue;
            }
            // Sutherland–Hodgman against the near plane z + w ≥ 0 (linear in clip space).
            std::array<glm::dvec4, 4> poly;
            int count = 0;
            for (int i = 0; i < 3; ++i) {
                const glm::dvec4& p = v[static_cast<size_t>(i)];
                const glm::dvec4& q = v[static_cast<size_t>((i + 1) % 3)];
                const double dp = p.z + p.w, dq = q.z + q.w;
                if (dp >= 0)
                    poly[static_cast<size_t>(count++)] = p;
                if ((dp >= 0) != (dq >= 0))
                    poly[static_cast<size_t>(count++)] = p + (q - p) * (dp / (dp - dq));
            }
            if (count < 3)
                continue;
            const ScreenVertex s0 = toScreen(poly[0]);
            for (int i = 1; i + 1 < count; ++i)
                drawTriangle(s0, toScreen(poly[static_cast<size_t>(i)]),
                             toScreen(poly[static_cast<size_t>(i + 1)]), id, target);
        }
    }
    out.depth_m.assign(n, 0.0f);
    for (size_t p = 0; p < n; ++p) {
        if (out.object[p] >= 0) {
            out.depth_m[p] = 1.0f / inv_depth[p];
            ++out.object_pixels[static_cast<size_t>(out.object[p])];
        }
    }
}

void depthPlanes(const DepthRaster& raster, ImageRgba8& high, ImageRgba8& low) {
    high.resize(raster.width, raster.height);
    low.resize(raster.width, raster.height);
    for (int y = 0; y < raster.height; ++y) {
        uint8_t* h = high.row(y);
        uint8_t* l = low.row(y);
        for (int x = 0; x < raster.width; ++x) {
            const float d = raster.depth_m[static_cast<size_t>(y) * raster.width + x];
            const long q = d > 0.0f ? std::min(65534l, std::lround(d / kDepthStepM)) : 65535l;
            const auto hb = static_cast<uint8_t>(q >> 8);
            auto lb = static_cast<uint8_t>(q & 255);
            if (hb & 1u)
                lb = static_cast<uint8_t>(255 - lb);
            for (int c = 0; c < 3; ++c) {
                h[4 * x + c] = hb;
                l[4 * x + c] = lb;
            }
            h[4 * x + 3] = 255;
            l[4 * x + 3] = 255;
        }
    }
}

void halveImage(const ImageRgba8& in, ImageRgba8& out) {
    const int w = (in.width() + 1) / 2;
    const int h = (in.height() + 1) / 2;
    out.resize(w, h);
    for (int y = 0; y < h; ++y) {
        const int ya = 2 * y;
        const int yb = std::min(2 * y + 1, in.height() - 1);
        const uint8_t* ra = in.row(ya);
        const uint8_t* rb = in.row(yb);
        uint8_t* o = out.row(y);
        for (int x = 0; x < w; ++x) {
            const int xa = 2 * x;
            const int xb = std::min(2 * x + 1, in.width() - 1);
            for (int c = 0; c < 4; ++c) {
                // Duplicated samples at an odd edge weigh the existing ones twice: the mean of
                // what exists.
                const int sum = ra[4 * xa + c] + ra[4 * xb + c] + rb[4 * xa + c] + rb[4 * xb + c];
                o[4 * x + c] = static_cast<uint8_t>((sum + 2) / 4);
            }
        }
    }
}

}  // namespace qvr
