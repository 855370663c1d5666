// OpenGL 4.5 core rendering of a Scene: one vertex and index buffer, mipmapped textures and
// lightmaps, one draw per batch that survives CPU frustum culling, into an FBO of the view's
// size; timer and primitive queries around the draws. Functions come from GLVND's libOpenGL.
#include "qvr/render/gl_renderer.h"

#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <map>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include "egl_context.h"
#include "qvr/core/clock.h"
#include "qvr/render/draw_list.h"

namespace qvr {

namespace {

// GL_ARB_pipeline_statistics_query tokens (not in glcorearb.h before GL 4.6).
constexpr GLenum kClippingInputPrimitives = 0x82F6;
constexpr GLenum kClippingOutputPrimitives = 0x82F7;
constexpr GLenum kFragmentShaderInvocations = 0x82F4;

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec2 a_uv;
layout(location = 2) in vec2 a_lightmap_uv;
layout(location = 3) in vec4 a_color;
layout(location = 0) uniform mat4 u_view_projection;
out vec2 v_uv;
out vec2 v_lightmap_uv;
out vec4 v_color;
void main() {
    v_uv = a_uv;
    v_lightmap_uv = a_lightmap_uv;
    v_color = a_color;
    gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

// Texture × lightmap × vertex colour, as Quake III's default lightmapped stage; batches without
// a texture or lightmap bind a 1×1 white one, so one program serves every batch.
constexpr const char* kFragmentShader = R"(#version 450 core
in vec2 v_uv;
in vec2 v_lightmap_uv;
in vec4 v_color;
layout(binding = 0) uniform sampler2D u_texture;
layout(binding = 1) uniform sampler2D u_lightmap;
layout(location = 1) uniform float u_lightmap_gain;
layout(location = 0) out vec4 o_color;
void main() {
    vec3 albedo = texture(u_texture, v_uv).rgb;
    vec3 light = min(texture(u_lightmap, v_lightmap_uv).rgb * u_lightmap_gain, vec3(1.0));
    o_color = vec4(albedo * light * v_color.rgb, 1.0);
}
)";

// The counting pass: clip-space positions only.
constexpr const char* kCountVertexShader = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 0) uniform mat4 u_view_projection;
void main() {
    gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

// Sutherland–Hodgman in homogeneous clip space: a triangle clipped by six planes has at most
// 3 + 6 vertices. Inclusive tests (≥ 0) make the volume closed, so a triangle that only touches
// a plane counts, as in the CPU definition.
constexpr const char* kCountGeometryShader = R"(#version 450 core
layout(triangles) in;
layout(points, max_vertices = 1) out;
float planeDistance(int plane, vec4 p) {
    float c = plane < 2 ? p.x : (plane < 4 ? p.y : p.z);
    return (plane % 2 == 0) ? p.w + c : p.w - c;
}
void main() {
    vec4 poly[9];
    vec4 next[9];
    poly[0] = gl_in[0].gl_Position;
    poly[1] = gl_in[1].gl_Position;
    poly[2] = gl_in[2].gl_Position;
    int n = 3;
    for (int plane = 0; plane < 6; ++plane) {
        int m = 0;
        for (int i = 0; i < n; ++i) {
            vec4 a = poly[i];
            vec4 b = poly[(i + 1) % n];
            float da = planeDistance(plane, a);
            float db = planeDistance(plane, b);
            if (da >= 0.0)
                next[m++] = a;
            if ((da >= 0.0) != (db >= 0.0))
                next[m++] = mix(a, b, da / (da - db));
        }
        n = m;
        if (n == 0)
            return;
        for (int i = 0; i < n; ++i)
            poly[i] = next[i];
    }
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    EmitVertex();
    EndPrimitive();
}
)";

// A shader after compiling or a program after linking (`status`: GL_COMPILE_STATUS or
// GL_LINK_STATUS, read with get_iv): itself, or, deleted, an error with its info log.
template <typename GetIv, typename GetLog, typename Delete>
Expected<GLuint> builtOrError(GLuint object, GLenum status, GetIv get_iv, GetLog get_log,
                              Delete destroy, const char* failure) {
    GLint ok = GL_FALSE;
    get_iv(object, status, &ok);
    if (ok == GL_TRUE)
        return object;
    char log[2048] = {};
    get_log(object, sizeof(log), nullptr, log);
    destroy(object);
    return makeError(fmt::format("GL: {}: {}", failure, log));
}

Expected<GLuint> compileShader(GLenum type, const char* source) {
    const GLuint shader = glCreateShader(type);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    return builtOrError(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog,
                        glDeleteShader, "shader compilation failed");
}

int mipLevels(int width, int height) {
    int levels = 1;
    for (int s = std::max(width, height); s > 1; s >>= 1)
        ++levels;
    return levels;
}

struct Framebuffer {
    int width = 0;  // the storage's size; a render uses its lower-left view-sized corner
    int height = 0;
    GLuint fbo = 0;
    GLuint color = 0;
    GLuint depth = 0;
    // With multisampling: the single-sample target the samples are resolved into for read-back.
    GLuint resolve_fbo = 0;
    GLuint resolve_color = 0;
};

}  // namespace

struct GlRenderer::Impl {
    std::unique_ptr<EglContext> egl;
    GlRendererOptions options;
    GlInfo info;
    GLuint program = 0;
    GLuint vao = 0;
    GLuint vertex_buffer = 0;
    GLuint index_buffer = 0;
    GLuint white = 0;
    std::vector<GLuint> textures;
    std::vector<GLuint> lightmaps;
    std::vector<SceneBatch> batches;
    DrawList draw_list;
    // One framebuffer per sample count that only grows, each render drawing into its corner:
    // LIWC moves the fovea in half degrees, and a framebuffer per size made every move's first
    // frame allocate and first-touch fresh storage (27 ms at 24.5° and 45 ms at 29.5° on
    // llvmpipe, 2CylinderEngine, against 1-2 ms once allocated), which the controller read as
    // the cost of the larger fovea.
    std::map<int, Framebuffer> framebuffers;
    GLuint query_time = 0;
    GLuint query_primitives = 0;
    GLuint query_clip_in = 0;
    GLuint query_clip_out = 0;
    GLuint query_fragments = 0;
    GLuint count_program = 0;
    GLuint query_count = 0;

    ~Impl() {
        if (!egl || !egl->makeCurrent())
            return;
        releaseScene();
        for (auto& [size, fb] : framebuffers)
            releaseFramebuffer(fb);
        const GLuint queries[] = {query_time, query_primitives, query_clip_in, query_clip_out,
                                  query_fragments};
        glDeleteQueries(5, queries);
        glDeleteTextures(1, &white);
        glDeleteVertexArrays(1, &vao);
        glDeleteProgram(program);
        glDeleteProgram(count_program);
        glDeleteQueries(1, &query_count);
    }

    void releaseScene() {
        glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
        glDeleteTextures(static_cast<GLsizei>(lightmaps.size()), lightmaps.data());
        textures.clear();
        lightmaps.clear();
        glDeleteBuffers(1, &vertex_buffer);
        glDeleteBuffers(1, &index_buffer);
        vertex_buffer = index_buffer = 0;
        batches.clear();
        draw_list = {};
    }

    static void releaseFramebuffer(Framebuffer& fb) {
        glDeleteFramebuffers(1, &fb.fbo);
        glDeleteRenderbuffers(1, &fb.color);
        glDeleteRenderbuffers(1, &fb.depth);
        glDeleteFramebuffers(1, &fb.resolve_fbo);
        glDeleteRenderbuffers(1, &fb.resolve_color);
        fb = {};
    }

    Status init() {
        const char* vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
        const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
        if (version == nullptr)
            return makeError(
                "GL: no function table behind the EGL context (libOpenGL without a "
                "GL vendor library?)");
        info.egl_platform = egl->platform();
        info.vendor = vendor != nullptr ? vendor : "";
        info.renderer = renderer != nullptr ? renderer : "";
        info.version = version;
        GLint n = 0;
        glGetIntegerv(GL_NUM_EXTENSIONS, &n);
        for (GLint i = 0; i < n; ++i) {
            const char* ext = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, i));
            if (ext != nullptr && std::strcmp(ext, "GL_ARB_pipeline_statistics_query") == 0)
                info.pipeline_statistics = true;
        }
        GLint max_samples = 1;
        glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
        info.max_samples = max_samples;
        if (options.msaa_samples < 1 || options.msaa_samples > max_samples)
            return makeError(
                fmt::format("render: {} samples per pixel asked for; the driver "
                            "offers 1 to {}",
                            options.msaa_samples, max_samples));
        if (!(options.lod_error_px >= 0.0f && options.lod_error_px <= 1000.0f))
            return makeError(
                fmt::format("render: LOD error of {} pixels asked for; give 0 (off) to 1000",
                            options.lod_error_px));
        GLint max_rb = 0;
        GLint max_vp[2] = {0, 0};
        glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
        glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_vp);
        info.max_framebuffer_px = std::min({max_rb, max_vp[0], max_vp[1]});
        if (Status st = checkGl("limits query"); !st)
            return st;

        auto shading = linkProgram(kVertexShader, nullptr, kFragmentShader);
        if (!shading)
            return Error{shading.error()};
        program = *shading;
        auto counting = linkProgram(kCountVertexShader, kCountGeometryShader, nullptr);
        if (!counting)
            return Error{counting.error()};
        count_program = *counting;

        glCreateVertexArrays(1, &vao);
        // Attribute layout of SceneVertex, bound to whatever vertex buffer upload() creates.
        glEnableVertexArrayAttrib(vao, 0);
        glEnableVertexArrayAttrib(vao, 1);
        glEnableVertexArrayAttrib(vao, 2);
        glEnableVertexArrayAttrib(vao, 3);
        glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(SceneVertex, position));
        glVertexArrayAttribFormat(vao, 1, 2, GL_FLOAT, GL_FALSE, offsetof(SceneVertex, uv));
        glVertexArrayAttribFormat(vao, 2, 2, GL_FLOAT, GL_FALSE,
                                  offsetof(SceneVertex, lightmap_uv));
        glVertexArrayAttribFormat(vao, 3, 4, GL_UNSIGNED_BYTE, GL_TRUE,
                                  offsetof(SceneVertex, color));
        for (GLuint a = 0; a < 4; ++a)
            glVertexArrayAttribBinding(vao, a, 0);

        const uint8_t white_texel[4] = {255, 255, 255, 255};
        glCreateTextures(GL_TEXTURE_2D, 1, &white);
        glTextureStorage2D(white, 1, GL_RGBA8, 1, 1);
        glTextureSubImage2D(white, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white_texel);

        if (Status st = checkGl("program and texture set-up"); !st)
            return st;
        // glGenQueries rather than glCreateQueries: Mesa 22's glCreateQueries rejects the
        // pipeline-statistics targets with GL_INVALID_ENUM; glBeginQuery gives them a type.
        glGenQueries(1, &query_time);
        glGenQueries(1, &query_primitives);
        glGenQueries(1, &query_count);
        if (info.pipeline_statistics) {
            glGenQueries(1, &query_clip_in);
            glGenQueries(1, &query_clip_out);
            glGenQueries(1, &query_fragments);
        }
        return checkGl("query creation");
    }

    static Expected<GLuint> linkProgram(const char* vertex, const char* geometry,
                                        const char* fragment) {
        const std::pair<GLenum, const char*> stages[] = {{GL_VERTEX_SHADER, vertex},
                                                         {GL_GEOMETRY_SHADER, geometry},
                                                         {GL_FRAGMENT_SHADER, fragment}};
        const GLuint prog = glCreateProgram();
        for (const auto& [type, source] : stages) {
            if (source == nullptr)
                continue;
            auto shader = compileShader(type, source);
            if (!shader) {
                glDeleteProgram(prog);
                return Error{shader.error()};
            }
            glAttachShader(prog, *shader);
            // Flagged for deletion; freed with the program.
            glDeleteShader(*shader);
        }
        glLinkProgram(prog);
        return builtOrError(prog, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog,
                            glDeleteProgram, "program link failed");
    }

    static Status checkGl(const char* what) {
        const GLenum e = glGetError();
        if (e == GL_NO_ERROR)
            return Status::success();
        return makeError(
            fmt::format("GL error 0x{:04x} during {}", static_cast<unsigned>(e), what));
    }

    Expected<GLuint> uploadTexture(const SceneTexture& t, bool repeat, const char* kind) {
        const size_t expected_bytes = static_cast<size_t>(std::max(t.width, 0)) *
                                      static_cast<size_t>(std::max(t.height, 0)) * 4;
        if (t.width <= 0 || t.height <= 0 || t.rgba.size() != expected_bytes)
            return makeError(fmt::format("render: {} '{}' is {}x{} with {} bytes of RGBA8", kind,
                                         t.name, t.width, t.height, t.rgba.size()));
        GLuint tex = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, mipLevels(t.width, t.height), GL_RGBA8, t.width, t.height);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        // Rows go up in the order stored, so v = 0 is the image's first (top) row.
        glTextureSubImage2D(tex, 0, 0, 0, t.width, t.height, GL_RGBA, GL_UNSIGNED_BYTE,
                            t.rgba.data());
        glGenerateTextureMipmap(tex);
        // Trilinear filtering: minified texels average instead of aliasing into noise the
        // periphery's video encoder would spend bits on.
        glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        const GLint wrap = repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
        glTextureParameteri(tex, GL_TEXTURE_WRAP_S, wrap);
        glTextureParameteri(tex, GL_TEXTURE_WRAP_T, wrap);
        return tex;
    }

    Status upload(const Scene& scene) {
        if (Status s = checkDrawable(scene); !s)
            return s;
        DrawList list = buildDrawList(scene);
        if (options.lod_error_px > 0.0f)
            buildLods(list, scene);
        if (Status s = egl->makeCurrent(); !s)
            return s;
        releaseScene();
        for (const SceneTexture& t : scene.textures) {
            auto tex = uploadTexture(t, true, "texture");
            if (!tex)
                return Error{tex.error()};
            textures.push_back(*tex);
        }
        for (const SceneTexture& t : scene.lightmaps) {
            auto tex = uploadTexture(t, false, "lightmap");
            if (!tex)
                return Error{tex.error()};
            lightmaps.push_back(*tex);
        }
        glCreateBuffers(1, &vertex_buffer);
        glCreateBuffers(1, &index_buffer);
        // Zero-size immutable storage is an error in GL; an empty scene keeps a 1-byte buffer.
        // The scene's vertices, then the ones its LOD levels add.
        const size_t vertex_count = scene.vertices.size() + list.lod_vertices.size();
        glNamedBufferStorage(
            vertex_buffer,
            std::max<GLsizeiptr>(1, static_cast<GLsizeiptr>(vertex_count * sizeof(SceneVertex))),
            nullptr, GL_DYNAMIC_STORAGE_BIT);
        if (!scene.vertices.empty())
            glNamedBufferSubData(
                vertex_buffer, 0,
                static_cast<GLsizeiptr>(scene.vertices.size() * sizeof(SceneVertex)),
                scene.vertices.data());
        if (!list.lod_vertices.empty())
            glNamedBufferSubData(
                vertex_buffer, static_cast<GLintptr>(scene.vertices.size() * sizeof(SceneVertex)),
                static_cast<GLsizeiptr>(list.lod_vertices.size() * sizeof(SceneVertex)),
                list.lod_vertices.data());
        glNamedBufferStorage(index_buffer,
                             std::max<GLsizeiptr>(1, static_cast<GLsizeiptr>(list.indices.size() *
                                                                             sizeof(uint32_t))),
                             list.indices.empty() ? nullptr : list.indices.data(), 0);
        glVertexArrayVertexBuffer(vao, 0, vertex_buffer, 0, sizeof(SceneVertex));
        glVertexArrayElementBuffer(vao, index_buffer);
        batches = scene.batches;
        draw_list = std::move(list);
        return checkGl("scene upload");
    }

    Expected<Framebuffer*> framebufferFor(int width, int height, int samples) {
        auto it = framebuffers.find(samples);
        if (it != framebuffers.end() && width <= it->second.width && height <= it->second.height)
            return &it->second;
        // Grow with a quarter's headroom so a fovea climbing in half degrees does not
        // reallocate at every step; never past the driver's limit.
        auto grown = [&](int want, int have) {
            if (want <= have)
                return have;
            const int headroom = static_cast<int>(std::ceil(want * 1.25));
            return std::min(std::max(headroom, want), std::max(want, info.max_framebuffer_px));
        };
        const int have_w = it != framebuffers.end() ? it->second.width : 0;
        const int have_h = it != framebuffers.end() ? it->second.height : 0;
        width = grown(width, have_w);
        height = grown(height, have_h);
        if (it != framebuffers.end()) {
            releaseFramebuffer(it->second);
            framebuffers.erase(it);
        }
        Framebuffer fb;
        fb.width = width;
        fb.height = height;
        auto storage = [&](GLuint rb, GLenum format, int n) {
            if (n > 1)
                glNamedRenderbufferStorageMultisample(rb, n, format, width, height);
            else
                glNamedRenderbufferStorage(rb, format, width, height);
        };
        glCreateRenderbuffers(1, &fb.color);
        storage(fb.color, GL_RGBA8, samples);
        glCreateRenderbuffers(1, &fb.depth);
        storage(fb.depth, GL_DEPTH_COMPONENT24, samples);
        glCreateFramebuffers(1, &fb.fbo);
        glNamedFramebufferRenderbuffer(fb.fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, fb.color);
        glNamedFramebufferRenderbuffer(fb.fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, fb.depth);
        GLenum status = glCheckNamedFramebufferStatus(fb.fbo, GL_FRAMEBUFFER);
        if (status == GL_FRAMEBUFFER_COMPLETE && samples > 1) {
            glCreateRenderbuffers(1, &fb.resolve_color);
            storage(fb.resolve_color, GL_RGBA8, 1);
            glCreateFramebuffers(1, &fb.resolve_fbo);
            glNamedFramebufferRenderbuffer(fb.resolve_fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                           fb.resolve_color);
            status = glCheckNamedFramebufferStatus(fb.resolve_fbo, GL_FRAMEBUFFER);
        }
        if (status != GL_FRAMEBUFFER_COMPLETE) {
            releaseFramebuffer(fb);
            return makeError(
                fmt::format("GL: {}x{} framebuffer with {} samples incomplete "
                            "(0x{:04x})",
                            width, height, samples, static_cast<unsigned>(status)));
        }
        return &framebuffers.emplace(samples, fb).first->second;
    }

    Expected<uint64_t> countTrianglesInFrustum(const RenderView& view) {
        if (Status s = egl->makeCurrent(); !s)
            return Error{s.error()};
        // Drawing needs a complete framebuffer even with rasterization discarded; the surfaceless
        // context has no default one.
        auto fb = framebufferFor(1, 1, 1);
        if (!fb)
            return Error{fb.error()};
        glBindFramebuffer(GL_FRAMEBUFFER, (*fb)->fbo);
        glUseProgram(count_program);
        const glm::mat4 view_projection = view.viewProjection();
        glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(view_projection));
        glBindVertexArray(vao);
        glEnable(GL_RASTERIZER_DISCARD);
        glBeginQuery(GL_PRIMITIVES_GENERATED, query_count);
        for (const SceneBatch& b : batches) {
            if (b.index_count < 3)
                continue;
            const uintptr_t offset = static_cast<uintptr_t>(b.first_index) * sizeof(uint32_t);
            glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(b.index_count), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(offset));
        }
        glEndQuery(GL_PRIMITIVES_GENERATED);
        glDisable(GL_RASTERIZER_DISCARD);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        GLuint64 count = 0;
        glGetQueryObjectui64v(query_count, GL_QUERY_RESULT, &count);
        if (Status s = checkGl("triangle counting"); !s)
            return Error{s.error()};
        return static_cast<uint64_t>(count);
    }

    Expected<RenderStats> render(const RenderView& view, ImageRgba8& out) {
        RenderStats stats;
        if (out.width() != view.width_px || out.height() != view.height_px)
            out.resize(std::max(view.width_px, 0), std::max(view.height_px, 0));
        if (view.width_px <= 0 || view.height_px <= 0)
            return stats;
        if (view.width_px > info.max_framebuffer_px || view.height_px > info.max_framebuffer_px)
            return makeError(fmt::format("render: a {}x{} view exceeds the driver's {} px limit",
                                         view.width_px, view.height_px, info.max_framebuffer_px));
        if (Status s = egl->makeCurrent(); !s)
            return Error{s.error()};
        auto fb = framebufferFor(view.width_px, view.height_px, options.msaa_samples);
        if (!fb)
            return Error{fb.error()};

        const Stopwatch t0;
        glBindFramebuffer(GL_FRAMEBUFFER, (*fb)->fbo);
        glViewport(0, 0, view.width_px, view.height_px);
        glScissor(0, 0, view.width_px, view.height_px);
        glEnable(GL_SCISSOR_TEST);  // the clear touches only the view's corner
        glClearColor(kClearRgba[0] / 255.0f, kClearRgba[1] / 255.0f, kClearRgba[2] / 255.0f, 1.0f);
        glClearDepth(1.0);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        // Levels from different loaders disagree on winding; draw both sides.
        glDisable(GL_CULL_FACE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

        glUseProgram(program);
        const glm::mat4 view_projection = view.viewProjection();
        glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(view_projection));
        glUniform1f(1, options.lightmap_gain);
        glBindVertexArray(vao);

        const DrawSelection selection = selectDraws(draw_list, view, options.lod_error_px);
        glBeginQuery(GL_TIME_ELAPSED, query_time);
        glBeginQuery(GL_PRIMITIVES_GENERATED, query_primitives);
        if (info.pipeline_statistics) {
            glBeginQuery(kClippingInputPrimitives, query_clip_in);
            glBeginQuery(kClippingOutputPrimitives, query_clip_out);
            glBeginQuery(kFragmentShaderInvocations, query_fragments);
        }
        for (const DrawRange& d : selection.draws) {
            const SceneBatch& b = batches[d.batch];
            glBindTextureUnit(0, b.texture >= 0 ? textures[static_cast<size_t>(b.texture)] : white);
            glBindTextureUnit(1,
                              b.lightmap >= 0 ? lightmaps[static_cast<size_t>(b.lightmap)] : white);
            const uintptr_t offset = static_cast<uintptr_t>(d.first_index) * sizeof(uint32_t);
            glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(d.index_count), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(offset));
        }
        if (info.pipeline_statistics) {
            glEndQuery(kFragmentShaderInvocations);
            glEndQuery(kClippingOutputPrimitives);
            glEndQuery(kClippingInputPrimitives);
        }
        glEndQuery(GL_PRIMITIVES_GENERATED);
        glEndQuery(GL_TIME_ELAPSED);
        GLuint read_fbo = (*fb)->fbo;
        if ((*fb)->resolve_fbo != 0) {
            glBlitNamedFramebuffer((*fb)->fbo, (*fb)->resolve_fbo, 0, 0, view.width_px,
                                   view.height_px, 0, 0, view.width_px, view.height_px,
                                   GL_COLOR_BUFFER_BIT, GL_NEAREST);
            read_fbo = (*fb)->resolve_fbo;
        }
        glFinish();
        stats.render_ms = t0.elapsedMs();
        glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fbo);

        const Stopwatch t1;
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, view.width_px, view.height_px, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
        // GL's first row is the bottom one; images are stored top row first.
        const size_t stride = out.strideElems();
        std::vector<uint8_t> tmp(stride);
        for (int y = 0; y < view.height_px / 2; ++y) {
            uint8_t* a = out.row(y);
            uint8_t* b = out.row(view.height_px - 1 - y);
            std::memcpy(tmp.data(), a, stride);
            std::memcpy(a, b, stride);
            std::memcpy(b, tmp.data(), stride);
        }
        stats.readback_ms = t1.elapsedMs();

        GLuint64 elapsed_ns = 0;
        GLuint64 primitives = 0;
        glGetQueryObjectui64v(query_time, GL_QUERY_RESULT, &elapsed_ns);
        glGetQueryObjectui64v(query_primitives, GL_QUERY_RESULT, &primitives);
        stats.gpu_ms = static_cast<double>(elapsed_ns) * 1e-6;
        stats.primitives_generated = primitives;
        if (info.pipeline_statistics) {
            GLuint64 clip_in = 0;
            GLuint64 clip_out = 0;
            glGetQueryObjectui64v(query_clip_in, GL_QUERY_RESULT, &clip_in);
            glGetQueryObjectui64v(query_clip_out, GL_QUERY_RESULT, &clip_out);
            stats.clipping_input_primitives = clip_in;
            stats.clipping_output_primitives = clip_out;
            GLuint64 fragments = 0;
            glGetQueryObjectui64v(query_fragments, GL_QUERY_RESULT, &fragments);
            stats.fragment_invocations = fragments;
            stats.statistics = true;
        }
        stats.clusters_drawn = selection.clusters_drawn;
        stats.clusters_culled = selection.clusters_culled;
        stats.clusters_skipped = selection.clusters_skipped;
        stats.draw_calls = static_cast<uint32_t>(selection.draws.size());
        glDisable(GL_SCISSOR_TEST);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        if (Status s = checkGl("rendering"); !s)
            return Error{s.error()};
        return stats;
    }
};

Expected<std::unique_ptr<GlRenderer>> GlRenderer::create(const GlRendererOptions& options) {
    auto egl = EglContext::create();
    if (!egl)
        return Error{egl.error()};
    auto impl = std::make_unique<Impl>();
    impl->egl = std::move(*egl);
    impl->options = options;
    if (Status s = impl->init(); !s)
        return Error{s.error()};
    return std::unique_ptr<GlRenderer>(new GlRenderer(std::move(impl)));
}

GlRenderer::GlRenderer(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
GlRenderer::~GlRenderer() = default;

const GlInfo& GlRenderer::info() const {
    return m_impl->info;
}

std::string GlRenderer::name() const {
    return "opengl (" + m_impl->info.renderer + ")";
}

Status GlRenderer::upload(const Scene& scene) {
    return m_impl->upload(scene);
}

Expected<RenderStats> GlRenderer::render(const RenderView& view, ImageRgba8& out) {
    return m_impl->render(view, out);
}

Expected<uint64_t> GlRenderer::countTrianglesInFrustum(const RenderView& view) {
    return m_impl->countTrianglesInFrustum(view);
}

}  // namespace qvr
