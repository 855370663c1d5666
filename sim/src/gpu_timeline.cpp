// Two-priority GPU timeline (paper §2.3, Fig. 4-③).
#include "qvr/sim/gpu_timeline.h"

#include <algorithm>

#include "qvr/core/check.h"

namespace qvr {

GpuInterval GpuTimeline::runPass(double ready_ms, double work_ms) {
    QVR_CHECK(work_ms >= 0.0);
    const double start = std::max(ready_ms, m_pass_free_ms);
    const GpuInterval iv{start, start + work_ms};
    m_pass_free_ms = iv.end_ms;
    m_busy_ms += work_ms;
    if (work_ms > 0.0)
        m_passes.push_back(iv);
    return iv;
}

double GpuTimeline::earliestRenderStartMs(double ready_ms) const {
    double t = std::max(ready_ms, m_render_free_ms);
    for (const GpuInterval& p : m_passes) {
        if (p.end_ms <= t)
            continue;
        if (p.start_ms > t)
            break;
        t = p.end_ms;
    }
    return t;
}

RenderSlot GpuTimeline::runRender(double ready_ms, double work_ms, double preempt_overhead_ms) {
    QVR_CHECK(work_ms >= 0.0);
    double t = std::max(ready_ms, m_render_free_ms);
    // Passes that ended before this rendering could start no longer matter to anyone: later
    // rendering starts no earlier than this one.
    while (!m_passes.empty() && m_passes.front().end_ms <= t)
        m_passes.pop_front();
    RenderSlot slot;
    double remaining = work_ms;
    bool started = false;
    for (const GpuInterval& p : m_passes) {
        if (p.end_ms <= t)
            continue;
        if (p.start_ms <= t) {
            // The cores are busy with a pass when the work becomes ready: it waits.
            t = p.end_ms;
            continue;
        }
        if (!started) {
            slot.start_ms = t;
            started = true;
        }
        if (p.start_ms >= t + remaining)
            break;
        // The pass arrives mid-render: the render is switched out and resumes after it.
        remaining -= p.start_ms - t;
        t = p.end_ms + preempt_overhead_ms;
        ++slot.preemptions;
        slot.overhead_ms += preempt_overhead_ms;
    }
    if (!started)
        slot.start_ms = t;
    slot.end_ms = t + remaining;
    m_render_free_ms = slot.end_ms;
    m_busy_ms += work_ms + slot.overhead_ms;
    return slot;
}

}  // namespace qvr
