// Quake III IBSP 46 parser. Layout (little-endian), from the game's qfiles.h:
//   header   "IBSP", int32 version = 46, 17 × {int32 offset, int32 length}
//   lump 0   entities: text, { "key" "value" … } blocks
//   lump 1   shaders: 72-byte records {char name[64]; int32 surface_flags, content_flags}
//   lump 10  vertices: 44-byte records {float xyz[3], st[2], lightmap_st[2], normal[3]; u8 rgba[4]}
//   lump 11  mesh indices: int32, relative to a face's first vertex
//   lump 13  faces: 104-byte records {int32 shader, fog, type, first_vertex, vertex_count,
//            first_index, index_count, lightmap, lm_x, lm_y, lm_w, lm_h; float lm_origin[3],
//            lm_vecs[3][3]; int32 patch_width, patch_height}
//   lump 14  lightmaps: 128 × 128 RGB8 each
// Every offset, length, count and index is checked before use; any violation is an error.
#include "qvr/scene/bsp_loader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "append_batch.h"
#include "image_decode.h"
#include "md3.h"
#include "quake_items.h"
#include "shader_script.h"

namespace qvr {

namespace {

static_assert(std::endian::native == std::endian::little, "BSP reader assumes little-endian");

constexpr int kBspVersion = 46;
constexpr int kLumpCount = 17;
constexpr size_t kHeaderBytes = 8 + kLumpCount * 8;
constexpr size_t kShaderBytes = 72;
constexpr size_t kVertexBytes = 44;
constexpr size_t kFaceBytes = 104;
constexpr int kLightmapSide = 128;
constexpr size_t kLightmapBytes = kLightmapSide * kLightmapSide * 3;
// Farther than any Quake III map reaches (MAX_WORLD_COORD is 65536); beyond it a file is bogus.
constexpr float kMaxCoordUnits = 1.0e6f;

enum LumpId {
    kEntities = 0,
    kShaders = 1,
    kVertices = 10,
    kMeshIndices = 11,
    kFaces = 13,
    kLightmaps = 14,
};

constexpr std::array<const char*, kLumpCount> kLumpNames = {
    "entities",     "shaders", "planes",    "nodes",         "leafs",     "leaf faces",
    "leaf brushes", "models",  "brushes",   "brush sides",   "vertices",  "mesh indices",
    "effects",      "faces",   "lightmaps", "light volumes", "visibility"};

// Surface flags (surfaceflags.h) of shaders that are never drawn.
constexpr int32_t kSurfSky = 0x4;
constexpr int32_t kSurfNoDraw = 0x80;
constexpr int32_t kSurfHint = 0x100;
constexpr int32_t kSurfSkip = 0x200;
constexpr int32_t kContentsFog = 0x40;

enum FaceType { kPolygon = 1, kPatch = 2, kMesh = 3, kFlare = 4 };

template <typename T>
T load(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
}

struct Lump {
    const uint8_t* data = nullptr;
    size_t bytes = 0;
    size_t count = 0;  // records
};

struct RawFace {
    int32_t shader, fog, type, first_vertex, vertex_count, first_index, index_count, lightmap;
    int32_t patch_width, patch_height;
};

RawFace readFace(const uint8_t* p) {
    RawFace f;
    f.shader = load<int32_t>(p + 0);
    f.fog = load<int32_t>(p + 4);
    f.type = load<int32_t>(p + 8);
    f.first_vertex = load<int32_t>(p + 12);
    f.vertex_count = load<int32_t>(p + 16);
    f.first_index = load<int32_t>(p + 20);
    f.index_count = load<int32_t>(p + 24);
    f.lightmap = load<int32_t>(p + 28);
    f.patch_width = load<int32_t>(p + 96);
    f.patch_height = load<int32_t>(p + 100);
    return f;
}

// Quake III's R_ColorShiftLightingBytes: scale up, then if a channel overflows scale all three
// down together so the hue survives.
void colorShift(uint8_t* rgb, int shift) {
    if (shift <= 0)
        return;
    int r = rgb[0] << shift, g = rgb[1] << shift, b = rgb[2] << shift;
    const int m = std::max({r, g, b});
    if (m > 255) {
        r = r * 255 / m;
        g = g * 255 / m;
        b = b * 255 / m;
    }
    rgb[0] = static_cast<uint8_t>(r);
    rgb[1] = static_cast<uint8_t>(g);
    rgb[2] = static_cast<uint8_t>(b);
}

bool finite3(const float* v) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

std::string printable(const uint8_t* p, size_t n) {
    std::string s;
    for (size_t i = 0; i < n; ++i)
        s += (p[i] >= 32 && p[i] < 127) ? static_cast<char>(p[i]) : '?';
    return s;
}

// Biquadratic Bézier blend of nine control vertices (row-major 3×3) at (u, v).
SceneVertex bezier(const SceneVertex* const cp[9], float u, float v) {
    const float bu[3] = {(1 - u) * (1 - u), 2 * u * (1 - u), u * u};
    const float bv[3] = {(1 - v) * (1 - v), 2 * v * (1 - v), v * v};
    SceneVertex out;
    out.position = glm::vec3(0);
    out.normal = glm::vec3(0);
    glm::vec4 color(0);
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) {
            const float w = bu[i] * bv[j];
            const SceneVertex& c = *cp[j * 3 + i];
            out.position += w * c.position;
            out.normal += w * c.normal;
            out.uv += w * c.uv;
            out.lightmap_uv += w * c.lightmap_uv;
            color += w * glm::vec4(c.color);
        }
    }
    const float len = glm::length(out.normal);
    out.normal = len > 1e-6f ? out.normal / len : glm::vec3(0, 1, 0);
    out.color = glm::u8vec4(glm::clamp(color + 0.5f, glm::vec4(0), glm::vec4(255)));
    return out;
}

class BspParser {
public:
    BspParser(std::span<const uint8_t> bytes, const GameFileSystem* files,
              const SceneLoadOptions& opts, BspStats& stats)
        : m_bytes(bytes), m_files(files), m_opts(opts), m_stats(stats) {}

    Expected<Scene> run(const std::string& name);

private:
    Status readHeader();
    Status lump(int id, size_t record_bytes, Lump& out);
    Status readVertices();
    Status readLightmaps(Scene& scene);
    Status readFaces(Scene& scene);
    Status addPatch(int face_index, const RawFace& f, std::vector<uint32_t>& out, Scene& scene);
    int textureFor(int shader, Scene& scene);
    int textureForName(const std::string& shader_name, Scene& scene);
    void readEntities(Scene& scene);
    void addItems(Scene& scene);
    Status addItemModel(const std::string& md3_path, float scale, const glm::vec3& origin_units,
                        Scene& scene);
    Status budget(uint64_t more_triangles, int face_index);

    std::span<const uint8_t> m_bytes;
    const GameFileSystem* m_files;
    const SceneLoadOptions& m_opts;
    BspStats& m_stats;
    std::array<std::pair<int32_t, int32_t>, kLumpCount> m_dir{};
    Lump m_shaders, m_vertices, m_indices, m_faces, m_lightmaps, m_entities;
    std::vector<SceneVertex> m_bsp_vertices;
    std::map<int, int> m_texture_of_shader;
    std::map<std::string, int> m_texture_of_path;
    ShaderLibrary m_shader_library;
    bool m_shader_library_loaded = false;
    struct ItemEntity {
        std::string classname;
        glm::vec3 origin_units{0.0f};
    };
    std::vector<ItemEntity> m_items;
    std::map<std::string, std::vector<detail::Md3Surface>> m_md3_of_path;
    uint64_t m_triangles = 0;
};

Status BspParser::readHeader() {
    if (m_bytes.size() < kHeaderBytes)
        return makeError(
            fmt::format("truncated header: the file has {} bytes, the IBSP header "
                        "needs {}",
                        m_bytes.size(), kHeaderBytes));
    if (std::memcmp(m_bytes.data(), "IBSP", 4) != 0)
        return makeError(fmt::format("not a Quake III BSP: magic is \"{}\", expected \"IBSP\"",
                                     printable(m_bytes.data(), 4)));
    const int32_t version = load<int32_t>(m_bytes.data() + 4);
    if (version != kBspVersion)
        return makeError(fmt::format("IBSP version {} is not supported (Quake III Arena is {})",
                                     version, kBspVersion));
    for (int i = 0; i < kLumpCount; ++i) {
        const uint8_t* p = m_bytes.data() + 8 + 8 * i;
        m_dir[static_cast<size_t>(i)] = {load<int32_t>(p), load<int32_t>(p + 4)};
    }
    return Status::success();
}

Status BspParser::lump(int id, size_t record_bytes, Lump& out) {
    const auto [offset, length] = m_dir[static_cast<size_t>(id)];
    const char* lname = kLumpNames[static_cast<size_t>(id)];
    if (offset < 0 || length < 0)
        return makeError(fmt::format("lump {} ({}): negative offset {} or length {}", id, lname,
                                     offset, length));
    const uint64_t end = static_cast<uint64_t>(offset) + static_cast<uint64_t>(length);
    if (end > m_bytes.size())
        return makeError(fmt::format("lump {} ({}): bytes [{}, {}) lie outside the {}-byte file",
                                     id, lname, offset, end, m_bytes.size()));
    if (static_cast<size_t>(length) % record_bytes != 0)
        return makeError(
            fmt::format("lump {} ({}): length {} is not a multiple of its {}-byte "
                        "records",
                        id, lname, length, record_bytes));
    out.data = m_bytes.data() + offset;
    out.bytes = static_cast<size_t>(length);
    out.count = out.bytes / record_bytes;
    return Status::success();
}

Status BspParser::readVertices() {
    m_bsp_vertices.resize(m_vertices.count);
    for (size_t i = 0; i < m_vertices.count; ++i) {
        const uint8_t* p = m_vertices.data + i * kVertexBytes;
        float f[10];
        std::memcpy(f, p, sizeof(f));
        if (!finite3(f) || std::fabs(f[0]) > kMaxCoordUnits || std::fabs(f[1]) > kMaxCoordUnits ||
            std::fabs(f[2]) > kMaxCoordUnits)
            return makeError(
                fmt::format("vertex {}: position ({}, {}, {}) is not finite or beyond "
                            "{} units",
                            i, f[0], f[1], f[2], kMaxCoordUnits));
        SceneVertex& v = m_bsp_vertices[i];
        v.position = quakeToScene(glm::vec3(f[0], f[1], f[2]));
        const auto finiteOr0 = [](float x) { return std::isfinite(x) ? x : 0.0f; };
        v.uv = glm::vec2(finiteOr0(f[3]), finiteOr0(f[4]));
        v.lightmap_uv = glm::vec2(finiteOr0(f[5]), finiteOr0(f[6]));
        glm::vec3 n(f[7], f[8], f[9]);
        const float len = finite3(&f[7]) ? glm::length(n) : 0.0f;
        v.normal = len > 1e-6f && std::isfinite(len) ? glm::vec3(n.x, n.z, -n.y) / len
                                                     : glm::vec3(0, 1, 0);
        uint8_t rgba[4];
        std::memcpy(rgba, p + 40, 4);
        colorShift(rgba, m_opts.lightmap_overbright_bits);
        v.color = glm::u8vec4(rgba[0], rgba[1], rgba[2], rgba[3]);
    }
    return Status::success();
}

Status BspParser::readLightmaps(Scene& scene) {
    if (!m_opts.load_lightmaps)
        return Status::success();
    scene.lightmaps.reserve(m_lightmaps.count);
    for (size_t i = 0; i < m_lightmaps.count; ++i) {
        SceneTexture t;
        t.name = fmt::format("lightmap{}", i);
        t.width = kLightmapSide;
        t.height = kLightmapSide;
        t.rgba.resize(static_cast<size_t>(kLightmapSide * kLightmapSide) * 4);
        const uint8_t* src = m_lightmaps.data + i * kLightmapBytes;
        for (int k = 0; k < kLightmapSide * kLightmapSide; ++k) {
            uint8_t rgb[3] = {src[3 * k], src[3 * k + 1], src[3 * k + 2]};
            colorShift(rgb, m_opts.lightmap_overbright_bits);
            std::memcpy(&t.rgba[4 * static_cast<size_t>(k)], rgb, 3);
            t.rgba[4 * static_cast<size_t>(k) + 3] = 255;
        }
        scene.lightmaps.push_back(std::move(t));
    }
    return Status::success();
}

int BspParser::textureFor(int shader, Scene& scene) {
    if (!m_opts.load_textures || m_files == nullptr)
        return -1;
    if (const auto it = m_texture_of_shader.find(shader); it != m_texture_of_shader.end())
        return it->second;
    const uint8_t* rec = m_shaders.data + static_cast<size_t>(shader) * kShaderBytes;
    const std::string shader_name(reinterpret_cast<const char*>(rec),
                                  strnlen(reinterpret_cast<const char*>(rec), 64));
    const int index = textureForName(shader_name, scene);
    m_texture_of_shader[shader] = index;
    return index;
}

int BspParser::textureForName(const std::string& shader_name, Scene& scene) {
    // The game tries the shader name as an image first, then the shader script's image.
    std::vector<std::string> bases = {stripImageExtension(normalizeGamePath(shader_name))};
    if (!m_shader_library_loaded) {
        m_shader_library.load(*m_files);
        m_shader_library_loaded = true;
    }
    if (std::string img = m_shader_library.imageFor(shader_name); !img.empty())
        bases.push_back(img);
    int index = -1;
    for (const auto& base : bases) {
        for (const char* ext : {".tga", ".jpg", ".png"}) {
            const std::string path = base + ext;
            // Shaders sharing one image share one texture.
            if (const auto it = m_texture_of_path.find(path); it != m_texture_of_path.end()) {
                index = it->second;
                break;
            }
            const auto bytes = m_files->read(path);
            if (!bytes)
                continue;
            auto tex = decodeImage(*bytes, path, m_opts.max_texture_px);
            if (!tex)
                continue;
            index = static_cast<int>(scene.textures.size());
            scene.textures.push_back(std::move(*tex));
            m_texture_of_path[path] = index;
            break;
        }
        if (index >= 0)
            break;
    }
    if (index < 0) {
        ++m_stats.shaders_without_image;
        m_stats.missing_images.push_back(shader_name);
    }
    return index;
}

Status BspParser::budget(uint64_t more_triangles, int face_index) {
    m_triangles += more_triangles;
    if (m_triangles > m_opts.max_triangles)
        return makeError(
            fmt::format("face {}: the level would exceed the limit of {} triangles "
                        "(lower the patch level)",
                        face_index, m_opts.max_triangles));
    return Status::success();
}

Status BspParser::addPatch(int face_index, const RawFace& f, std::vector<uint32_t>& out,
                           Scene& scene) {
    const int w = f.patch_width, h = f.patch_height;
    if (w < 3 || h < 3 || w > kMaxPatchSide || h > kMaxPatchSide || w % 2 == 0 || h % 2 == 0)
        return makeError(fmt::format("face {}: patch size {}x{} is invalid (odd, 3…{} per side)",
                                     face_index, w, h, kMaxPatchSide));
    if (f.vertex_count != w * h)
        return makeError(fmt::format("face {}: patch {}x{} needs {} vertices, the face has {}",
                                     face_index, w, h, w * h, f.vertex_count));
    const int level = m_opts.patch_level;
    const int pw = (w - 1) / 2, ph = (h - 1) / 2;
    const int nx = pw * level + 1, ny = ph * level + 1;
    if (Status s = budget(2ull * static_cast<uint64_t>(nx - 1) * static_cast<uint64_t>(ny - 1),
                          face_index);
        !s)
        return s;
    const SceneVertex* cp = m_bsp_vertices.data() + f.first_vertex;
    const uint64_t base64 = scene.vertices.size();
    if (base64 + static_cast<uint64_t>(nx) * static_cast<uint64_t>(ny) > UINT32_MAX)
        return makeError(fmt::format("face {}: the level exceeds 2^32 vertices", face_index));
    const uint32_t base = static_cast<uint32_t>(base64);
    for (int gy = 0; gy < ny; ++gy) {
        const int py = std::min(gy / level, ph - 1);
        const float v = static_cast<float>(gy - py * level) / static_cast<float>(level);
        for (int gx = 0; gx < nx; ++gx) {
            const int px = std::min(gx / level, pw - 1);
            const float u = static_cast<float>(gx - px * level) / static_cast<float>(level);
            const SceneVertex* c[9];
            for (int j = 0; j < 3; ++j)
                for (int i = 0; i < 3; ++i)
                    c[j * 3 + i] = &cp[(2 * py + j) * w + 2 * px + i];
            scene.vertices.push_back(bezier(c, u, v));
        }
    }
    // Orient the triangles so that their geometric normals agree with the interpolated vertex
    // normals, i.e. counter-clockwise seen from the side the level is lit and played on.
    const size_t first = out.size();
    double agreement = 0.0;
    for (int gy = 0; gy + 1 < ny; ++gy) {
        for (int gx = 0; gx + 1 < nx; ++gx) {
            const uint32_t a = base + static_cast<uint32_t>(gy * nx + gx);
            const uint32_t b = a + 1;
            const uint32_t c = a + static_cast<uint32_t>(nx);
            const uint32_t d = c + 1;
            for (const auto& t :
                 {std::array<uint32_t, 3>{a, c, b}, std::array<uint32_t, 3>{b, c, d}}) {
                const glm::vec3& p0 = scene.vertices[t[0]].position;
                const glm::vec3 n = glm::cross(scene.vertices[t[1]].position - p0,
                                               scene.vertices[t[2]].position - p0);
                agreement += glm::dot(n, scene.vertices[t[0]].normal + scene.vertices[t[1]].normal +
                                             scene.vertices[t[2]].normal);
                out.insert(out.end(), t.begin(), t.end());
            }
        }
    }
    if (agreement < 0.0) {
        for (size_t i = first; i < out.size(); i += 3)
            std::swap(out[i + 1], out[i + 2]);
    }
    return Status::success();
}

Status BspParser::readFaces(Scene& scene) {
    // (shader, lightmap, is_patch) → triangle indices; one batch each.
    std::map<std::tuple<int, int, bool>, std::vector<uint32_t>> buckets;
    m_stats.faces = static_cast<int>(m_faces.count);
    for (size_t fi = 0; fi < m_faces.count; ++fi) {
        const int face_index = static_cast<int>(fi);
        const RawFace f = readFace(m_faces.data + fi * kFaceBytes);
        if (f.type != kPolygon && f.type != kMesh && f.type != kPatch) {
            ++m_stats.faces_flare_or_unknown;
            continue;
        }
        if (f.shader < 0 || static_cast<size_t>(f.shader) >= m_shaders.count) {
            ++m_stats.faces_bad_shader;
            continue;
        }
        const uint8_t* srec = m_shaders.data + static_cast<size_t>(f.shader) * kShaderBytes;
        const int32_t surface_flags = load<int32_t>(srec + 64);
        const int32_t content_flags = load<int32_t>(srec + 68);
        if ((surface_flags & (kSurfSky | kSurfNoDraw | kSurfHint | kSurfSkip)) != 0 ||
            (content_flags & kContentsFog) != 0) {
            ++m_stats.faces_sky_or_nodraw;
            continue;
        }
        if (f.vertex_count < 0 || f.first_vertex < 0 || f.index_count < 0 || f.first_index < 0)
            return makeError(fmt::format(
                "face {}: negative count or offset (first vertex {}, "
                "{} vertices, first index {}, {} indices)",
                face_index, f.first_vertex, f.vertex_count, f.first_index, f.index_count));
        if (static_cast<uint64_t>(f.first_vertex) + static_cast<uint64_t>(f.vertex_count) >
            m_bsp_vertices.size())
            return makeError(
                fmt::format("face {}: vertices [{}, {}) past the {} in the vertex lump", face_index,
                            f.first_vertex, static_cast<int64_t>(f.first_vertex) + f.vertex_count,
                            m_bsp_vertices.size()));
        if (f.vertex_count == 0) {
            ++m_stats.faces_empty;
            continue;
        }
        const int lightmap = (m_opts.load_lightmaps && f.lightmap >= 0 &&
                              static_cast<size_t>(f.lightmap) < m_lightmaps.count)
                                 ? f.lightmap
                                 : -1;
        const bool is_patch = f.type == kPatch;
        std::vector<uint32_t>& out = buckets[{f.shader, lightmap, is_patch}];
        if (is_patch) {
            if (Status s = addPatch(face_index, f, out, scene); !s)
                return s;
        } else {
            if (static_cast<uint64_t>(f.first_index) + static_cast<uint64_t>(f.index_count) >
                m_indices.count)
                return makeError(fmt::format(
                    "face {}: indices [{}, {}) past the {} in the mesh "
                    "index lump",
                    face_index, f.first_index, static_cast<int64_t>(f.first_index) + f.index_count,
                    m_indices.count));
            if (f.index_count % 3 != 0)
                return makeError(fmt::format("face {}: {} indices is not whole triangles",
                                             face_index, f.index_count));
            if (f.index_count == 0) {
                ++m_stats.faces_empty;
                continue;
            }
            if (Status s = budget(static_cast<uint64_t>(f.index_count / 3), face_index); !s)
                return s;
            const uint8_t* ip = m_indices.data + static_cast<size_t>(f.first_index) * 4;
            for (int k = 0; k < f.index_count; k += 3) {
                uint32_t tri[3];
                for (int j = 0; j < 3; ++j) {
                    const int32_t idx = load<int32_t>(ip + 4 * static_cast<size_t>(k + j));
                    if (idx < 0 || idx >= f.vertex_count)
                        return makeError(
                            fmt::format("face {}: index {} = {} is outside the "
                                        "face's {} vertices",
                                        face_index, k + j, idx, f.vertex_count));
                    tri[j] = static_cast<uint32_t>(f.first_vertex + idx);
                }
                // Quake III's front faces wind clockwise; qvr's (OpenGL's default) wind
                // counter-clockwise.
                out.insert(out.end(), {tri[0], tri[2], tri[1]});
            }
        }
        ++m_stats.faces_drawn;
    }
    for (auto& [key, idx] : buckets) {
        if (idx.empty())
            continue;
        SceneBatch b;
        b.texture = textureFor(std::get<0>(key), scene);
        b.lightmap = std::get<1>(key);
        b.is_patch = std::get<2>(key);
        detail::appendBatch(scene, b, idx);
    }
    return Status::success();
}

// Entity text: a sequence of { "key" "value" ... } blocks. Parsing stops quietly at the first
// malformed token: entities only supply spawn points, and a level stays drawable without them.
void BspParser::readEntities(Scene& scene) {
    const std::string_view text(reinterpret_cast<const char*>(m_entities.data), m_entities.bytes);
    size_t pos = 0;
    auto skipSpace = [&] {
        while (pos < text.size() &&
               (std::isspace(static_cast<unsigned char>(text[pos])) || text[pos] == '\0'))
            ++pos;
    };
    auto quoted = [&](std::string& out) {
        skipSpace();
        if (pos >= text.size() || text[pos] != '"')
            return false;
        const size_t end = text.find('"', pos + 1);
        if (end == std::string_view::npos)
            return false;
        out.assign(text.substr(pos + 1, end - pos - 1));
        pos = end + 1;
        return true;
    };
    for (;;) {
        skipSpace();
        if (pos >= text.size() || text[pos] != '{')
            return;
        ++pos;
        std::map<std::string, std::string> kv;
        for (;;) {
            skipSpace();
            if (pos < text.size() && text[pos] == '}') {
                ++pos;
                break;
            }
            std::string key, value;
            if (!quoted(key) || !quoted(value))
                return;
            kv[key] = value;
        }
        const std::string& cls = kv["classname"];
        const bool spawn = cls == "info_player_deathmatch" || cls == "info_player_start";
        const bool item = !detail::quakeItemModel(cls).md3_paths.empty();
        if (!spawn && !item)
            continue;
        float o[3];
        char tail = 0;
        if (std::sscanf(kv["origin"].c_str(), "%f %f %f %c", &o[0], &o[1], &o[2], &tail) != 3 ||
            !finite3(o) || std::fabs(o[0]) > kMaxCoordUnits || std::fabs(o[1]) > kMaxCoordUnits ||
            std::fabs(o[2]) > kMaxCoordUnits)
            continue;
        if (item) {
            m_items.push_back({cls, glm::vec3(o[0], o[1], o[2])});
            continue;
        }
        float angle = 0.0f;
        if (kv.count("angle")) {
            angle = std::strtof(kv["angle"].c_str(), nullptr);
        } else if (kv.count("angles")) {
            float pitch = 0, yaw = 0, roll = 0;
            if (std::sscanf(kv["angles"].c_str(), "%f %f %f", &pitch, &yaw, &roll) >= 2)
                angle = yaw;
        }
        if (!std::isfinite(angle))
            angle = 0.0f;
        SpawnPoint sp;
        sp.position_m = quakeToScene(glm::vec3(o[0], o[1], o[2] + kQuakeSpawnEyeUnits));
        // Quake's yaw is counter-clockwise from +x (east); qvr's is about +y from −z, and
        // Quake's +y (north) maps to −z, so qvr yaw = Quake yaw − 90°.
        float yaw = std::fmod(angle - 90.0f, 360.0f);
        if (yaw > 180.0f)
            yaw -= 360.0f;
        if (yaw <= -180.0f)
            yaw += 360.0f;
        sp.yaw_deg = yaw;
        scene.spawns.push_back(sp);
    }
}

Expected<Scene> BspParser::run(const std::string& name) {
    if (m_opts.patch_level < 1 || m_opts.patch_level > 64)
        return makeError(fmt::format("patch level {} is outside 1…64", m_opts.patch_level));
    if (m_opts.lightmap_overbright_bits < 0 || m_opts.lightmap_overbright_bits > 4)
        return makeError(fmt::format("lightmap overbright bits {} is outside 0…4",
                                     m_opts.lightmap_overbright_bits));
    if (Status s = readHeader(); !s)
        return makeError(s.error());
    const std::pair<int, size_t> lumps[] = {
        {kEntities, 1},    {kShaders, kShaderBytes}, {kVertices, kVertexBytes},
        {kMeshIndices, 4}, {kFaces, kFaceBytes},     {kLightmaps, kLightmapBytes}};
    Lump* targets[] = {&m_entities, &m_shaders, &m_vertices, &m_indices, &m_faces, &m_lightmaps};
    for (size_t i = 0; i < std::size(lumps); ++i) {
        if (Status s = lump(lumps[i].first, lumps[i].second, *targets[i]); !s)
            return makeError(s.error());
    }
    Scene scene;
    scene.name = name;
    if (Status s = readVertices(); !s)
        return makeError(s.error());
    scene.vertices = m_bsp_vertices;
    if (Status s = readLightmaps(scene); !s)
        return makeError(s.error());
    if (Status s = readFaces(scene); !s)
        return makeError(s.error());
    readEntities(scene);
    if (m_opts.load_items && m_files != nullptr)
        addItems(scene);
    return scene;
}

// Every item entity's models, unrotated at its origin; a model the game files lack or cannot
// parse leaves the item out (counted), the level stays drawable.
void BspParser::addItems(Scene& scene) {
    for (const ItemEntity& item : m_items) {
        const detail::QuakeItemModel model = detail::quakeItemModel(item.classname);
        bool placed = true;
        for (const std::string& path : model.md3_paths)
            placed = addItemModel(path, model.scale, item.origin_units, scene).ok() && placed;
        ++(placed ? m_stats.items_placed : m_stats.items_without_model);
    }
}

Status BspParser::addItemModel(const std::string& md3_path, float scale,
                               const glm::vec3& origin_units, Scene& scene) {
    auto it = m_md3_of_path.find(md3_path);
    if (it == m_md3_of_path.end()) {
        const auto bytes = m_files->read(md3_path);
        if (!bytes)
            return makeError(fmt::format("{}: not in the game files", md3_path));
        auto surfaces = detail::parseMd3(*bytes);
        if (!surfaces)
            return makeError(fmt::format("{}: {}", md3_path, surfaces.error()));
        it = m_md3_of_path.emplace(md3_path, std::move(*surfaces)).first;
    }
    for (const detail::Md3Surface& surface : it->second) {
        if (Status s = budget(surface.indices.size() / 3, -1); !s)
            return s;
        const auto base = static_cast<uint32_t>(scene.vertices.size());
        for (size_t v = 0; v < surface.positions.size(); ++v) {
            SceneVertex sv;
            sv.position = quakeToScene(origin_units + scale * surface.positions[v]);
            const glm::vec3& n = surface.normals[v];
            sv.normal = glm::vec3(n.x, n.z, -n.y);  // quakeToScene's axes, unscaled
            sv.uv = surface.uvs[v];
            scene.vertices.push_back(sv);
        }
        std::vector<uint32_t> indices;
        indices.reserve(surface.indices.size());
        for (uint32_t i : surface.indices)
            indices.push_back(base + i);
        SceneBatch b;
        b.texture = surface.shader.empty() ? -1 : textureForName(surface.shader, scene);
        b.interactive = true;
        detail::appendBatch(scene, b, indices);
    }
    return Status::success();
}

}  // namespace

Expected<Scene> parseBsp(std::span<const uint8_t> bytes, const std::string& scene_name,
                         const GameFileSystem* files, const SceneLoadOptions& opts,
                         BspStats* stats) {
    BspStats local;
    BspParser parser(bytes, files, opts, stats != nullptr ? *stats : local);
    auto scene = parser.run(scene_name);
    if (!scene)
        return makeError(fmt::format("{}: {}", scene_name, scene.error()));
    return scene;
}

}  // namespace qvr
