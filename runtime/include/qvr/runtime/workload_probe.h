// The frame description LIWC reads before rendering (paper §4.1's "hardware intermediate data"):
// triangles per eccentricity ring from the scene's BVH for both eyes' frusta, the full-resolution
// pixels per ring, and the periphery's bits per pixel as measured on the streams so far. The same
// frames are written as a workload trace so `qvr sim` can replay a run.
#pragma once

#include <memory>
#include <vector>

#include "qvr/core/pose.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/draw_list.h"
#include "qvr/scene/triangle_bvh.h"
#include "qvr/workload/workload.h"

namespace qvr::runtime {

class WorkloadProbe {
public:
    // ring_deg · rings must lie in [45, 180] (the trace format's rule).
    WorkloadProbe(const HmdProfile& profile, std::shared_ptr<const TriangleBvh> bvh,
                  double ring_deg = 1.0, int rings = 120);

    const WorkloadHeader& header() const { return m_header; }

    // Count triangles per ring from the renderer's draw clusters at the level of detail a
    // full-resolution view draws (draw_list.h addTrianglesPerRing) instead of the BVH: what
    // the fovea will submit, at a cost that does not grow with e1 (docs/LIWC.md "Ring counts").
    void useClusters(std::shared_ptr<const DrawList> clusters, float lod_error_px);
    void setName(const std::string& name, const std::string& source);

    // Triangles are binned in rings up to count_to_deg only; everything beyond falls in the last
    // of those rings (the BVH then accepts whole subtrees there, which makes the query several
    // times cheaper). LIWC reads rings up to e1 + 5°; 180 counts every ring.
    WorkloadFrame frame(int64_t index, double time_ms, const Pose& head, const Gaze& gaze,
                        double count_to_deg = 180.0) const;

    // Folds one frame's measured periphery sizes (both eyes, bytes and layer pixels at s1/s2)
    // into the bits-per-pixel power law b·s^γ the next frames report.
    void observeBits(double middle_bytes, double middle_pixels, double s1, double outer_bytes,
                     double outer_pixels, double s2);

    // Pixels of both eyes per ring of eccentricity around the gaze (a grid of ≤ 128² samples).
    std::vector<double> pixelsPerRing(const Gaze& gaze) const;

private:
    HmdProfile m_profile;
    EyeGeometry m_geometry;
    // The pixel-ring grid's view directions and the pixels each stands for, fixed by the
    // profile: computed once, so a frame's pixel rings cost one dot product and one table
    // lookup a sample (RingOfCosine).
    struct PixelSample {
        glm::dvec3 direction;
        double pixels = 0.0;
    };
    std::vector<PixelSample> m_pixel_samples;
    // The ring of a direction from the cosine of its angle to the gaze, without an acos: ring k
    // holds the cosines in (cos((k+1)·ring_deg), cos(k·ring_deg)]. A table over [−1, 1] names
    // the ring of each bin's ends; a bin that straddles one ring edge compares once against it,
    // one that straddles several (near ±1 for narrow rings) searches the edges.
    class RingOfCosine {
    public:
        RingOfCosine(double ring_deg, int rings);
        int operator()(double c) const;

    private:
        int search(double c) const;
        std::vector<double> m_edges;  // cos(k·ring_deg) for k = 1 … rings−1, decreasing
        struct Bin {
            int low_ring;   // the ring at the bin's upper cosine (the smaller one)
            int high_ring;  // the ring at its lower cosine
        };
        std::vector<Bin> m_bins;
    };
    RingOfCosine m_ring_of_cosine;
    std::shared_ptr<const TriangleBvh> m_bvh;
    std::shared_ptr<const DrawList> m_clusters;
    float m_lod_error_px = 0.0f;
    WorkloadHeader m_header;
    double m_log_bits_at_1 = 0.0;  // log(bits per pixel at scale 1)
    double m_bits_exponent = 0.7;
};

}  // namespace qvr::runtime
