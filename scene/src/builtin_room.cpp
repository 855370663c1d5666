// builtin:room — a procedural stand-in for a game level: a textured room around a board of
// lathe-turned pieces, spheres and tori. Dense, curved geometry makes triangle counts vary
// strongly with the gaze (what LIWC reacts to), and the noise textures keep the periphery's
// video bitrate realistic.
#include "qvr/scene/builtin_scene.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "append_batch.h"

namespace qvr {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kTextureSide = 512;
constexpr float kSquareM = 0.5f;  // board square
constexpr int kBoardColumns = 8;

// Integer hash → [0, 1): the seed of the value noise below.
float hash2(int x, int y, int seed) {
    uint32_t h = static_cast<uint32_t>(x) * 374761393u + static_cast<uint32_t>(y) * 668265263u +
                 static_cast<uint32_t>(seed) * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    h ^= h >> 16;
    return static_cast<float>(h & 0xffffff) / 16777216.0f;
}

// Tileable value noise with period `period` cells, smoothstep-interpolated.
float valueNoise(float x, float y, int period, int seed) {
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    const float sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
    auto h = [&](int ix, int iy) {
        return hash2(((ix % period) + period) % period, ((iy % period) + period) % period, seed);
    };
    const float a = h(x0, y0) + (h(x0 + 1, y0) - h(x0, y0)) * sx;
    const float b = h(x0, y0 + 1) + (h(x0 + 1, y0 + 1) - h(x0, y0 + 1)) * sx;
    return a + (b - a) * sy;
}

// Fractal sum of octaves over the unit square, tileable; about [0, 1].
float fbm(float u, float v, int base_period, int seed) {
    float sum = 0, amp = 0.5f, norm = 0;
    int period = base_period;
    for (int o = 0; o < 5; ++o) {
        sum += amp * valueNoise(u * static_cast<float>(period), v * static_cast<float>(period),
                                period, seed + o);
        norm += amp;
        amp *= 0.5f;
        period *= 2;
    }
    return sum / norm;
}

SceneTexture makeTexture(const std::string& name,
                         const std::function<glm::vec3(float, float)>& shade) {
    SceneTexture t;
    t.name = name;
    t.width = kTextureSide;
    t.height = kTextureSide;
    t.rgba.resize(static_cast<size_t>(kTextureSide) * kTextureSide * 4);
    for (int y = 0; y < kTextureSide; ++y) {
        for (int x = 0; x < kTextureSide; ++x) {
            // Per-texel grain on top of the smooth pattern: real game textures carry detail
            // down to the texel, and that is what the periphery's video encoder pays for.
            const float grain = 0.92f + 0.16f * hash2(x, y, 1234);
            const glm::vec3 c =
                glm::clamp(grain * shade((static_cast<float>(x) + 0.5f) / kTextureSide,
                                         (static_cast<float>(y) + 0.5f) / kTextureSide),
                           glm::vec3(0), glm::vec3(1));
            uint8_t* p = &t.rgba[(static_cast<size_t>(y) * kTextureSide + x) * 4];
            p[0] = static_cast<uint8_t>(c.r * 255.0f + 0.5f);
            p[1] = static_cast<uint8_t>(c.g * 255.0f + 0.5f);
            p[2] = static_cast<uint8_t>(c.b * 255.0f + 0.5f);
            p[3] = 255;
        }
    }
    return t;
}

enum Material { kFloor, kWall, kCeiling, kBoard, kLightPiece, kDarkPiece, kMaterialCount };

std::vector<SceneTexture> makeTextures() {
    std::vector<SceneTexture> t(kMaterialCount);
    t[kFloor] = makeTexture("builtin/wood_planks", [](float u, float v) {
        const float plank = std::floor(v * 8.0f);
        const float grain = fbm(u * 0.25f + plank * 0.37f, v * 4.0f, 4, 11);
        const float rings = 0.5f + 0.5f * std::sin(40.0f * u + 12.0f * grain + plank);
        const float seam = std::fmod(v * 8.0f, 1.0f) < 0.03f ? 0.55f : 1.0f;
        return seam * glm::mix(glm::vec3(0.45f, 0.28f, 0.15f), glm::vec3(0.70f, 0.50f, 0.30f),
                               0.6f * rings + 0.4f * grain);
    });
    t[kWall] = makeTexture("builtin/brick", [](float u, float v) {
        const float row = std::floor(v * 16.0f);
        const float bu = u * 8.0f + (static_cast<int>(row) % 2 ? 0.5f : 0.0f);
        const bool mortar = std::fmod(v * 16.0f, 1.0f) < 0.08f || std::fmod(bu, 1.0f) < 0.04f;
        const float n = fbm(u, v, 16, 23);
        const float tint = hash2(static_cast<int>(std::floor(bu)) % 8, static_cast<int>(row), 5);
        if (mortar)
            return glm::vec3(0.75f, 0.73f, 0.68f) * (0.8f + 0.3f * n);
        return glm::mix(glm::vec3(0.55f, 0.22f, 0.15f), glm::vec3(0.72f, 0.38f, 0.25f), tint) *
               (0.7f + 0.5f * n);
    });
    t[kCeiling] = makeTexture("builtin/plaster", [](float u, float v) {
        return glm::vec3(0.85f, 0.84f, 0.80f) * (0.8f + 0.25f * fbm(u, v, 8, 41));
    });
    t[kBoard] = makeTexture("builtin/marble_board", [](float u, float v) {
        // One texture tile = 2×2 squares.
        const bool dark = (static_cast<int>(u * 2.0f) + static_cast<int>(v * 2.0f)) % 2 == 1;
        const float n = fbm(u, v, 4, 57);
        const float vein = std::pow(std::fabs(std::sin(12.0f * (u + v) + 9.0f * n)), 0.3f);
        return dark ? glm::vec3(0.12f, 0.16f, 0.14f) + 0.25f * (1.0f - vein)
                    : glm::vec3(0.92f, 0.90f, 0.86f) * (0.75f + 0.25f * vein);
    });
    t[kLightPiece] = makeTexture("builtin/ivory", [](float u, float v) {
        const float n = fbm(u, v, 8, 71);
        return glm::vec3(0.95f, 0.90f, 0.78f) * (0.8f + 0.2f * std::sin(30.0f * v + 6.0f * n));
    });
    t[kDarkPiece] = makeTexture("builtin/ebony", [](float u, float v) {
        const float n = fbm(u, v, 8, 83);
        return glm::vec3(0.20f, 0.12f, 0.08f) * (0.7f + 0.6f * n);
    });
    return t;
}

class Builder {
public:
    explicit Builder(Scene& scene) : m_scene(scene), m_indices(kMaterialCount) {}

    uint32_t vertex(const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv) {
        SceneVertex v;
        v.position = p;
        v.normal = glm::normalize(n);
        v.uv = uv;
        // Baked diffuse light from one key light plus ambient: the room has no lightmaps.
        const float lit = 0.45f + 0.55f * std::max(0.0f, glm::dot(v.normal, kLightDir));
        const auto c = static_cast<uint8_t>(std::clamp(lit * 255.0f, 0.0f, 255.0f));
        v.color = glm::u8vec4(c, c, c, 255);
        m_scene.vertices.push_back(v);
        return static_cast<uint32_t>(m_scene.vertices.size() - 1);
    }
    void triangle(Material m, uint32_t a, uint32_t b, uint32_t c) {
        // Lathe poles collapse a grid row to one point; those triangles have no area.
        const auto& v = m_scene.vertices;
        if (v[a].position == v[b].position || v[b].position == v[c].position ||
            v[a].position == v[c].position)
            return;
        m_indices[m].insert(m_indices[m].end(), {a, b, c});
    }
    // A grid of (nu+1)×(nv+1) vertices from f(u, v) → (position, normal); CCW seen from the
    // normal's side when (∂p/∂u × ∂p/∂v) points along the normal.
    void grid(Material m, int nu, int nv, glm::vec2 uv_scale,
              const std::function<std::pair<glm::vec3, glm::vec3>(float, float)>& f) {
        const uint32_t base = static_cast<uint32_t>(m_scene.vertices.size());
        for (int j = 0; j <= nv; ++j) {
            for (int i = 0; i <= nu; ++i) {
                const float u = static_cast<float>(i) / nu, v = static_cast<float>(j) / nv;
                const auto [p, n] = f(u, v);
                vertex(p, n, glm::vec2(u * uv_scale.x, v * uv_scale.y));
            }
        }
        for (int j = 0; j < nv; ++j) {
            for (int i = 0; i < nu; ++i) {
                const uint32_t a = base + static_cast<uint32_t>(j * (nu + 1) + i);
                const uint32_t b = a + 1, c = a + static_cast<uint32_t>(nu + 1), d = c + 1;
                triangle(m, a, b, d);
                triangle(m, a, d, c);
            }
        }
    }
    // An axis-aligned quad spanned by origin + s·du + t·dv, facing du × dv.
    void quad(Material m, glm::vec3 origin, glm::vec3 du, glm::vec3 dv, int nu, int nv,
              glm::vec2 uv_scale) {
        const glm::vec3 n = glm::normalize(glm::cross(du, dv));
        grid(m, nu, nv, uv_scale,
             [&](float u, float v) { return std::make_pair(origin + u * du + v * dv, n); });
    }
    // Surface of revolution about +y of the profile r(t), y(t), t ∈ [0, 1] bottom to top.
    void lathe(Material m, glm::vec3 base, int segments, int steps,
               const std::function<glm::vec2(float)>& profile) {
        grid(m, segments, steps, glm::vec2(2.0f, 1.0f), [&](float u, float v) {
            const float a = 2.0f * kPi * u;
            const glm::vec2 rp = profile(v);
            // Differences over the neighbouring rows, so the normals follow the tessellated
            // surface (and its winding) even where the profile has ridges.
            const float dt = 1.0f / static_cast<float>(steps);
            const glm::vec2 d = profile(std::min(v + dt, 1.0f)) - profile(std::max(v - dt, 0.0f));
            // Outward normal of the profile curve (r, y): rotate its tangent by −90°.
            glm::vec2 n2(d.y, -d.x);
            if (glm::length(n2) < 1e-9f)
                n2 = glm::vec2(1, 0);
            n2 = glm::normalize(n2);
            const glm::vec3 radial(std::sin(a), 0.0f, std::cos(a));
            return std::make_pair(base + glm::vec3(0, rp.y, 0) + rp.x * radial,
                                  n2.x * radial + glm::vec3(0, n2.y, 0));
        });
    }
    void sphere(Material m, glm::vec3 c, float r) {
        lathe(m, c - glm::vec3(0, r, 0), 48, 24, [r](float t) {
            const float th = kPi * t;
            return glm::vec2(r * std::sin(th), r - r * std::cos(th));
        });
    }
    void torus(Material m, glm::vec3 c, float major, float minor) {
        grid(m, 64, 24, glm::vec2(4.0f, 1.0f), [&](float u, float v) {
            const float a = 2.0f * kPi * u, b = 2.0f * kPi * v;
            const glm::vec3 radial(std::sin(a), 0.0f, std::cos(a));
            const glm::vec3 n = std::cos(b) * radial + glm::vec3(0, std::sin(b), 0);
            return std::make_pair(c + major * radial + minor * n, n);
        });
    }
    void finish() {
        for (int m = 0; m < kMaterialCount; ++m) {
            auto& idx = m_indices[static_cast<size_t>(m)];
            if (idx.empty())
                continue;
            SceneBatch b;
            b.texture = m;
            b.interactive = m == kLightPiece || m == kDarkPiece;  // the chess pieces
            detail::appendBatch(m_scene, b, idx);
        }
    }

private:
    static inline const glm::vec3 kLightDir = glm::normalize(glm::vec3(0.4f, 1.0f, 0.3f));
    Scene& m_scene;
    std::vector<std::vector<uint32_t>> m_indices;
};

// Chess-like lathe profiles, height h: a base, a waist and a distinctive top.
glm::vec2 pieceProfile(int kind, float t, float h) {
    const float base = 0.16f * h * (1.0f - std::clamp(t * 6.0f, 0.0f, 1.0f) * 0.35f);
    if (t < 0.15f)
        return glm::vec2(base * (t < 0.02f ? t / 0.02f : 1.0f) + 0.02f * h * std::sin(t * 60.0f),
                         t * h);
    const float s = (t - 0.15f) / 0.85f;  // 0…1 over the body
    float r = 0.0f;
    switch (kind) {
        case 0:  // pawn: a waist and a ball
            r = s < 0.6f ? 0.10f * h * (1.0f - 0.5f * s)
                         : 0.11f * h *
                               std::sqrt(std::max(0.0f, 1.0f - std::pow((s - 0.8f) / 0.2f, 2.0f)));
            break;
        case 1:  // rook: a straight tower with a flared, notched crown
            r = (s < 0.8f ? 0.09f * h : 0.12f * h * (1.0f + 0.15f * std::sin(s * 80.0f))) *
                (s > 0.97f ? 0.0f : 1.0f);
            break;
        case 2:  // bishop: a mitre
            r = s < 0.55f ? 0.08f * h * (1.0f - 0.4f * s)
                          : 0.09f * h * std::sin(kPi * std::min(1.0f, (s - 0.55f) / 0.45f + 0.1f));
            break;
        default:  // queen / king: a tall body with a ridged crown
            r = s < 0.7f ? 0.085f * h * (1.0f - 0.3f * s) + 0.01f * h * std::sin(s * 40.0f)
                         : 0.11f * h *
                               std::sqrt(std::max(0.0f, 1.0f - std::pow((s - 0.7f) / 0.3f, 2.0f))) *
                               (1.0f + 0.08f * std::sin(s * 120.0f));
            break;
    }
    return glm::vec2(std::max(0.0f, r), t * h);
}

}  // namespace

Scene makeBuiltinRoom(int objects) {
    objects = std::clamp(objects, 0, kMaxBuiltinObjects);
    Scene scene;
    scene.name = objects == 32 ? "builtin:room" : fmt::format("builtin:room?objects={}", objects);
    scene.textures = makeTextures();
    Builder b(scene);

    const int rows = std::max(8, (objects + kBoardColumns - 1) / kBoardColumns);
    const float board_w = kBoardColumns * kSquareM;
    const float board_d = static_cast<float>(rows) * kSquareM;
    const float half_x = std::max(6.0f, 0.5f * board_w + 3.0f);
    const float half_z = std::max(6.0f, 0.5f * board_d + 3.0f);
    const float height = 3.5f;
    const glm::vec2 wall_uv(2.0f * half_x / 2.0f, height / 2.0f);

    // Room: floor, ceiling, four walls, all facing inwards; tessellated so the counts vary
    // smoothly with the view rather than jumping by one huge triangle.
    b.quad(kFloor, {-half_x, 0, -half_z}, {0, 0, 2 * half_z}, {2 * half_x, 0, 0}, 24, 24,
           {half_z, half_x});
    b.quad(kCeiling, {-half_x, height, -half_z}, {2 * half_x, 0, 0}, {0, 0, 2 * half_z}, 12, 12,
           {half_x / 2, half_z / 2});
    b.quad(kWall, {half_x, height, -half_z}, {-2 * half_x, 0, 0}, {0, -height, 0}, 16, 4, wall_uv);
    b.quad(kWall, {-half_x, height, half_z}, {2 * half_x, 0, 0}, {0, -height, 0}, 16, 4, wall_uv);
    b.quad(kWall, {-half_x, height, -half_z}, {0, 0, 2 * half_z}, {0, -height, 0}, 16, 4,
           {half_z, height / 2.0f});
    b.quad(kWall, {half_x, height, half_z}, {0, 0, -2 * half_z}, {0, -height, 0}, 16, 4,
           {half_z, height / 2.0f});
    // The board: a slab 5 cm above the floor.
    const float top = 0.05f;
    const glm::vec3 corner(-0.5f * board_w, top, -0.5f * board_d);
    b.quad(kBoard, corner, {0, 0, board_d}, {board_w, 0, 0}, kBoardColumns, rows,
           {static_cast<float>(rows) / 2.0f, kBoardColumns / 2.0f});
    b.quad(kBoard, corner + glm::vec3(0, 0, board_d), {0, -top, 0}, {board_w, 0, 0}, 1, 1,
           {0.1f, 4.0f});

    // The first 32 objects stand as a chess game starts: back ranks and pawn ranks, dark on
    // the far side; further objects fill the middle rows, then rows added behind the board.
    constexpr int kRowOrder[8] = {0, 7, 1, 6, 2, 5, 3, 4};
    constexpr int kBackRank[8] = {1, 6, 2, 3, 4, 2, 6, 1};  // rook, knight, bishop, queen, king…
    for (int i = 0; i < objects; ++i) {
        const int col = i % kBoardColumns, slot = i / kBoardColumns;
        const int row = slot < 8 ? kRowOrder[slot] : slot;
        const glm::vec3 c = corner + glm::vec3((static_cast<float>(col) + 0.5f) * kSquareM, 0,
                                               (static_cast<float>(row) + 0.5f) * kSquareM);
        const Material m = row < 4 || (row >= 8 && row % 2 == 0) ? kDarkPiece : kLightPiece;
        int kind = static_cast<int>(hash2(col, row, 99) * 7.0f);  // middle and extra rows
        if (row == 0 || row == 7)
            kind = kBackRank[col];
        else if (row == 1 || row == 6)
            kind = 0;
        // Kinds: 0 pawn, 1 rook, 2 bishop, 3 queen, 4 king, 5 sphere, 6 torus ("knight").
        constexpr float kHeights[7] = {0.45f, 0.55f, 0.65f, 0.75f, 0.8f, 0.55f, 0.6f};
        const float h = kHeights[kind] * (0.95f + 0.1f * hash2(col, row, 7));
        if (kind < 5) {
            b.lathe(m, c, 64, 64,
                    [kind, h](float t) { return pieceProfile(std::min(kind, 3), t, h); });
        } else if (kind == 5) {
            // Sphere on a short pedestal.
            b.lathe(m, c, 48, 8, [h](float t) {
                return glm::vec2(0.12f * h * (1.2f - 0.5f * t), 0.2f * h * t);
            });
            b.sphere(m, c + glm::vec3(0, 0.2f * h + 0.16f * h, 0), 0.16f * h);
        } else {
            // "Knight": a torus standing on a base.
            b.lathe(m, c, 48, 8, [h](float t) {
                return glm::vec2(0.16f * h * (1.0f - 0.4f * t), 0.15f * h * t);
            });
            b.torus(m, c + glm::vec3(0, 0.15f * h + 0.06f * h, 0), 0.12f * h, 0.05f * h);
        }
    }
    b.finish();

    // Spawn points: standing behind each end of the board, looking across it.
    const float eye_m = 1.7f;
    scene.spawns.push_back({glm::vec3(0, eye_m, 0.5f * board_d + 1.5f), 0.0f});
    scene.spawns.push_back({glm::vec3(0, eye_m, -0.5f * board_d - 1.5f), 180.0f});
    scene.spawns.push_back({glm::vec3(0.5f * board_w + 1.5f, eye_m, 0), 90.0f});
    return scene;
}

Expected<Scene> makeBuiltinScene(const std::string& spec, int default_objects) {
    std::string name = spec;
    int objects = default_objects;
    if (const size_t q = spec.find('?'); q != std::string::npos) {
        name = spec.substr(0, q);
        const std::string query = spec.substr(q + 1);
        const std::string key = "objects=";
        if (query.rfind(key, 0) != 0)
            return makeError(
                fmt::format("builtin:{}: unknown option '{}' (only objects=N)", spec, query));
        const std::string value = query.substr(key.size());
        const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), objects);
        if (ec != std::errc() || ptr != value.data() + value.size() || objects < 0 ||
            objects > kMaxBuiltinObjects)
            return makeError(fmt::format("builtin:{}: objects must be an integer 0…{}", spec,
                                         kMaxBuiltinObjects));
    }
    if (name != "room")
        return makeError(fmt::format("builtin:{}: unknown built-in scene (available: room)", spec));
    if (objects < 0 || objects > kMaxBuiltinObjects)
        return makeError(
            fmt::format("builtin objects {} outside 0…{}", objects, kMaxBuiltinObjects));
    return makeBuiltinRoom(objects);
}

}  // namespace qvr
