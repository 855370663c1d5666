// The ground-truth cost of a frame on modelled hardware: what a frame really takes locally
// and remotely for a given layer plan. Policies never see this; they see its measurements.
// The local model charges triangles and shaded pixels of the fovea disc to a mobile GPU whose
// rates scale with clock frequency; the remote model is Eq. 2's bytes over throughput.
#pragma once

#include "qvr/workload/workload.h"

namespace qvr {

// A mobile GPU as throughput rates (paper Table 2: 8 unified shaders of 8 SIMD4 ALUs at
// 500 MHz). Rates are given at 500 MHz and scale linearly with the clock. Defaults and their
// calibration: docs/COST_MODEL.md.
struct GpuModel {
    double freq_mhz = 500.0;
    double triangles_per_ms_at_500 = 50'000.0;  // vertex shading + setup, both eyes counted
    double pixels_per_ms_at_500 = 150'000.0;    // shaded fragments
    double setup_ms = 0.3;                      // per-frame fixed cost (state, clears)

    double trianglesPerMs() const { return triangles_per_ms_at_500 * freq_mhz / 500.0; }
    double pixelsPerMs() const { return pixels_per_ms_at_500 * freq_mhz / 500.0; }
};

struct FrameCost {
    double local_ms = 0.0;
    double remote_ms = 0.0;
    double triangles_local = 0.0;  // in the fovea cone, both eyes
    double pixels_local = 0.0;     // shaded fovea pixels, both eyes
    PeripheryBytes bytes;
    double frameMs() const { return local_ms > remote_ms ? local_ms : remote_ms; }
};

class CostModel {
public:
    CostModel(const WorkloadHeader& header, GpuModel gpu, double throughput_bps);

    const GpuModel& gpu() const { return m_gpu; }
    double throughputBps() const { return m_throughput_bps; }
    void setThroughputBps(double bps) { m_throughput_bps = bps; }
    const LayerPlanner& planner() const { return m_planner; }

    // The frame's cost with the fovea at e1 (its plan is made here).
    FrameCost cost(const WorkloadFrame& frame, double e1_deg) const;
    FrameCost cost(const WorkloadFrame& frame, const LayerPlan& plan) const;
    // Everything rendered on the headset (the `local` design).
    double localOnlyMs(const WorkloadFrame& frame) const;

private:
    const WorkloadHeader& m_header;
    GpuModel m_gpu;
    double m_throughput_bps;
    LayerPlanner m_planner;
};

}  // namespace qvr
