// A renderer that takes at least `delay` per layer (the null renderer after a sleep): a server
// of a fixed, CPU-free cost per layer, for tests of timing and scheduling.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "qvr/render/renderer.h"

namespace qvr::runtime {

class SlowRenderer final : public Renderer {
public:
    explicit SlowRenderer(std::chrono::microseconds delay)
        : m_inner(makeNullRenderer()), m_delay(delay) {}
    std::string name() const override { return "slow-null"; }
    Status upload(const Scene& scene) override { return m_inner->upload(scene); }
    Expected<RenderStats> render(const RenderView& view, ImageRgba8& out) override {
        std::this_thread::sleep_for(m_delay);
        return m_inner->render(view, out);
    }

private:
    std::unique_ptr<Renderer> m_inner;
    std::chrono::microseconds m_delay;
};

}  // namespace qvr::runtime
