// A headless EGL display and OpenGL 4.5 core context without any window system surface.
#pragma once

#include <memory>
#include <string>

#include "qvr/core/expected.h"

namespace qvr {

class EglContext {
public:
    static Expected<std::unique_ptr<EglContext>> create();
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    // Makes the context current on the calling thread (a no-op when it already is).
    Status makeCurrent();
    const std::string& platform() const { return m_platform; }

private:
    EglContext() = default;
    void* m_display = nullptr;
    void* m_context = nullptr;
    std::string m_platform;
};

}  // namespace qvr
