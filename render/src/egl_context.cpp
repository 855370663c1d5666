// EGL set-up for headless rendering: the Mesa surfaceless platform first (no X, no Wayland, no
// DRM device needed; llvmpipe in a container), the default display as the fallback.
#include "egl_context.h"

#define EGL_NO_X11
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <mutex>

#if defined(__SANITIZE_ADDRESS__)
#define QVR_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QVR_ASAN 1
#endif
#endif
#if defined(QVR_ASAN)
#include <dlfcn.h>
#include <link.h>
#endif

#include <fmt/format.h>

namespace qvr {

namespace {

// EGL displays are per-process singletons and eglTerminate ends every context on one, so the
// display is terminated only when the last context on it goes.
std::mutex g_display_mutex;
int g_display_users = 0;

bool hasExtension(const char* list, const char* name) {
    if (list == nullptr)
        return false;
    const size_t n = std::strlen(name);
    for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + n, name)) {
        const bool starts = p == list || p[-1] == ' ';
        const bool ends = p[n] == '\0' || p[n] == ' ';
        if (starts && ends)
            return true;
    }
    return false;
}

std::string eglErrorText(const char* what) {
    return fmt::format("EGL: {} failed (error 0x{:04x})", what,
                       static_cast<unsigned>(eglGetError()));
}

#if defined(QVR_ASAN)
// ASan builds only. eglTerminate makes Mesa dlclose its driver, so by the time LeakSanitizer looks
// at exit the driver's globals are unmapped and stop counting as roots: Mesa 22.3's swrast_dri.so
// then shows up as two 56-byte blocks that point at each other (by the code that allocates them,
// gallium's u_mm heap from mmInit), reachable only from the driver's own globals, reported once per
// load. Their stack is one frame inside the unmapped driver, which LSan names as libasan, the test
// binary or "<unknown module>", so no suppression can name that library without also hiding our own
// leaks. Keeping every library loaded at this point mapped until exit (RTLD_NODELETE) is what a
// process that never terminates its display sees: those blocks stay reachable, and a leak in qvr,
// or in a library that is still loaded, is reported as before.
void keepLoadedLibrariesMappedForLeakSanitizer() {
    dl_iterate_phdr(
        [](dl_phdr_info* info, size_t, void*) -> int {
            if (info->dlpi_name != nullptr && info->dlpi_name[0] != '\0')
                dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
            return 0;
        },
        nullptr);
}
#endif

constexpr const char* kInstallHint =
    "; headless OpenGL needs EGL with Mesa's surfaceless platform (Debian: libegl1 libegl-mesa0 "
    "libgl1-mesa-dri libopengl0)";

}  // namespace

Expected<std::unique_ptr<EglContext>> EglContext::create() {
    // Declared before the lock so that on an error return the lock is released first and the
    // half-built context's destructor can take it.
    std::unique_ptr<EglContext> ctx(new EglContext());
    std::lock_guard<std::mutex> lock(g_display_mutex);
    EGLDisplay display = EGL_NO_DISPLAY;
    const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (hasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
        auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
            eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (get_platform_display != nullptr) {
            display =
                get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            ctx->m_platform = "surfaceless";
        }
    }
    EGLint major = 0, minor = 0;
    if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor) != EGL_TRUE)
        display = EGL_NO_DISPLAY;
    if (display == EGL_NO_DISPLAY) {
        display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        ctx->m_platform = "default";
        if (display == EGL_NO_DISPLAY)
            return makeError(std::string("EGL: no display") + kInstallHint);
        if (eglInitialize(display, &major, &minor) != EGL_TRUE)
            return makeError(eglErrorText("eglInitialize") + kInstallHint);
    }
    ++g_display_users;
    ctx->m_display = display;
#if defined(QVR_ASAN)
    keepLoadedLibrariesMappedForLeakSanitizer();
#endif

    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE)
        return makeError(eglErrorText("eglBindAPI(EGL_OPENGL_API)") + kInstallHint);

    const char* display_extensions = eglQueryString(display, EGL_EXTENSIONS);
    if (!hasExtension(display_extensions, "EGL_KHR_surfaceless_context"))
        return makeError(
            "EGL: the display lacks EGL_KHR_surfaceless_context, which off-screen "
            "rendering without a window needs");

    // A config is only needed to pick the API; the framebuffers are our own FBOs.
    EGLConfig config = nullptr;
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint num_configs = 0;
    if (eglChooseConfig(display, config_attribs, &config, 1, &num_configs) != EGL_TRUE ||
        num_configs < 1) {
        if (!hasExtension(display_extensions, "EGL_KHR_no_config_context"))
            return makeError("EGL: no config renders OpenGL" + std::string(kInstallHint));
        config = EGL_NO_CONFIG_KHR;
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                      4,
                                      EGL_CONTEXT_MINOR_VERSION,
                                      5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
    if (context == EGL_NO_CONTEXT)
        return makeError(eglErrorText("eglCreateContext (OpenGL 4.5 core)") +
                         "; the driver must offer OpenGL 4.5 core (Mesa ≥ 20 llvmpipe does)");
    ctx->m_context = context;
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE)
        return makeError(eglErrorText("eglMakeCurrent"));
    return ctx;
}

EglContext::~EglContext() {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    if (m_display == nullptr)
        return;
    if (m_context != nullptr) {
        if (eglGetCurrentContext() == m_context)
            eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(m_display, m_context);
    }
    if (--g_display_users == 0)
        eglTerminate(m_display);
}

Status EglContext::makeCurrent() {
    if (eglGetCurrentContext() == m_context)
        return Status::success();
    if (eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, m_context) != EGL_TRUE)
        return makeError(eglErrorText("eglMakeCurrent"));
    return Status::success();
}

}  // namespace qvr
