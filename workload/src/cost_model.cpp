// Ground-truth frame costs: the local GPU pays for the fovea cone's triangles and the fovea
// disc's shaded pixels; the remote side is the periphery's bytes over the link (Eq. 2's form).
#include "qvr/workload/cost_model.h"

#include <algorithm>

namespace qvr {

CostModel::CostModel(const WorkloadHeader& header, GpuModel gpu, double throughput_bps)
    : m_header(header), m_gpu(gpu), m_throughput_bps(throughput_bps), m_planner(header.profile) {
    QVR_CHECK(gpu.freq_mhz > 0 && gpu.triangles_per_ms_at_500 > 0 && gpu.pixels_per_ms_at_500 > 0);
    QVR_CHECK(throughput_bps > 0);
}

FrameCost CostModel::cost(const WorkloadFrame& frame, double e1_deg) const {
    return cost(frame, m_planner.plan(frame.gaze, e1_deg));
}

FrameCost CostModel::cost(const WorkloadFrame& frame, const LayerPlan& plan) const {
    FrameCost c;
    const double ring = m_header.ring_deg;
    if (plan.hasRemote()) {
        c.triangles_local = sumWithinDeg(frame.triangles_per_ring, ring, plan.e1_deg);
        c.pixels_local = sumWithinDeg(frame.pixels_per_ring, ring, plan.e1_deg);
    } else {
        c.triangles_local = sumTotal(frame.triangles_per_ring);
        c.pixels_local = sumTotal(frame.pixels_per_ring);
    }
    c.local_ms = m_gpu.setup_ms + c.triangles_local / m_gpu.trianglesPerMs() +
                 c.pixels_local / m_gpu.pixelsPerMs();
    c.bytes = peripheryBytes(m_header, frame, plan);
    c.remote_ms = c.bytes.total() * 8.0 / m_throughput_bps * 1000.0;
    return c;
}

double CostModel::localOnlyMs(const WorkloadFrame& frame) const {
    return m_gpu.setup_ms + sumTotal(frame.triangles_per_ring) / m_gpu.trianglesPerMs() +
           sumTotal(frame.pixels_per_ring) / m_gpu.pixelsPerMs();
}

}  // namespace qvr
