// The mobile GPU as a two-priority unit (paper §2.3, Fig. 4-③): composition and ATW passes
// run at high priority and preempt whatever rendering is on the cores; rendering fills the
// gaps between them. The contention of Fig. 4-③ is what this produces, not a constant.
#pragma once

#include <deque>

namespace qvr {

struct GpuInterval {
    double start_ms = 0.0;
    double end_ms = 0.0;
};

struct RenderSlot {
    double start_ms = 0.0;  // first cycle the work runs
    double end_ms = 0.0;    // last cycle, after every preemption
    int preemptions = 0;
    double overhead_ms = 0.0;  // context switches paid for the preemptions
};

class GpuTimeline {
public:
    // A screen-space pass: starts at `ready_ms` or when the previous pass ends, whichever is
    // later, preempting rendering. Passes are submitted in non-decreasing frame order.
    GpuInterval runPass(double ready_ms, double work_ms);
    // Rendering work that starts at `ready_ms` or after the previous rendering, and yields to
    // every pass already submitted, paying `preempt_overhead_ms` each time it is interrupted.
    RenderSlot runRender(double ready_ms, double work_ms, double preempt_overhead_ms);

    // When rendering that becomes ready at `ready_ms` would first run: after the previous
    // rendering and after any pass already occupying the cores then.
    double earliestRenderStartMs(double ready_ms) const;
    double renderFreeMs() const { return m_render_free_ms; }
    double passFreeMs() const { return m_pass_free_ms; }
    double busyMs() const { return m_busy_ms; }  // all work, passes and render and overhead

private:
    std::deque<GpuInterval> m_passes;  // sorted, non-overlapping
    double m_render_free_ms = 0.0;
    double m_pass_free_ms = 0.0;
    double m_busy_ms = 0.0;
};

}  // namespace qvr
