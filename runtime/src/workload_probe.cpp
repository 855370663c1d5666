// LIWC's per-frame input measured from the scene (paper §4.1): BVH ring counts and pixel rings.
#include "qvr/runtime/workload_probe.h"

#include <algorithm>
#include <cmath>

#include "qvr/render/camera.h"

namespace qvr::runtime {

namespace {
// Pixel rings are counted on a grid of this many samples per side at most; each sample stands
// for the pixels around it, so a frame costs ~16k direction tests whatever the resolution.
constexpr int kMaxPixelSamplesPerSide = 128;
// Bins of the cosine table: 2 / 8192 wide, narrower than a 1° ring's cosine span everywhere but
// within ~2° of the gaze or of its opposite, where the search takes over.
constexpr int kCosineBins = 8192;
}  // namespace

WorkloadProbe::RingOfCosine::RingOfCosine(double ring_deg, int rings) {
    constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
    for (int k = 1; k < rings; ++k)
        m_edges.push_back(std::cos(k * ring_deg * kRadPerDeg));
    m_bins.resize(kCosineBins);
    for (int b = 0; b < kCosineBins; ++b) {
        const double lo = -1.0 + 2.0 * b / kCosineBins, hi = -1.0 + 2.0 * (b + 1) / kCosineBins;
        m_bins[static_cast<size_t>(b)] = {search(std::min(hi, 1.0)), search(lo)};
    }
}

int WorkloadProbe::RingOfCosine::search(double c) const {
    // The number of edges at or above c: the edges decrease, so they form a prefix.
    const auto it = std::partition_point(m_edges.begin(), m_edges.end(),
                                         [c](double edge) { return edge >= c; });
    return static_cast<int>(it - m_edges.begin());
}

int WorkloadProbe::RingOfCosine::operator()(double c) const {
    c = std::clamp(c, -1.0, 1.0);
    const int b = std::min(kCosineBins - 1, static_cast<int>((c + 1.0) * (kCosineBins / 2)));
    const Bin& bin = m_bins[static_cast<size_t>(b)];
    if (bin.low_ring == bin.high_ring)
        return bin.low_ring;
    if (bin.high_ring == bin.low_ring + 1)
        return c <= m_edges[static_cast<size_t>(bin.low_ring)] ? bin.high_ring : bin.low_ring;
    return search(c);
}

WorkloadProbe::WorkloadProbe(const HmdProfile& profile, std::shared_ptr<const TriangleBvh> bvh,
                             double ring_deg, int rings)
    : m_profile(profile),
      m_geometry(profile),
      m_ring_of_cosine(ring_deg, rings),
      m_bvh(std::move(bvh)) {
    m_header.name = "qvr-run";
    m_header.source = "recorded by qvr run";
    m_header.profile = profile;
    m_header.ring_deg = ring_deg;
    m_header.rings = rings;
    m_header.scales = {1, 2, 4, 8, 16, 32};
    const int w = m_geometry.width(), h = m_geometry.height();
    const int step_x = std::max(1, (w + kMaxPixelSamplesPerSide - 1) / kMaxPixelSamplesPerSide);
    const int step_y = std::max(1, (h + kMaxPixelSamplesPerSide - 1) / kMaxPixelSamplesPerSide);
    for (int y0 = 0; y0 < h; y0 += step_y) {
        const int bh = std::min(step_y, h - y0);
        for (int x0 = 0; x0 < w; x0 += step_x) {
            const int bw = std::min(step_x, w - x0);
            // Both eyes share the gaze, hence 2×.
            m_pixel_samples.push_back(
                {m_geometry.directionAt(x0 + 0.5 * bw, y0 + 0.5 * bh), 2.0 * bw * bh});
        }
    }
}

void WorkloadProbe::useClusters(std::shared_ptr<const DrawList> clusters, float lod_error_px) {
    m_clusters = std::move(clusters);
    m_lod_error_px = lod_error_px;
}

void WorkloadProbe::setName(const std::string& name, const std::string& source) {
    m_header.name = name;
    m_header.source = source;
}

std::vector<double> WorkloadProbe::pixelsPerRing(const Gaze& gaze) const {
    // The same eccentricity as EyeGeometry::eccentricityDeg, the gaze's direction computed once.
    std::vector<double> rings(static_cast<size_t>(m_header.rings), 0.0);
    const glm::dvec3 g = m_geometry.gazeDirection(gaze);
    for (const PixelSample& s : m_pixel_samples)
        rings[static_cast<size_t>(m_ring_of_cosine(glm::dot(g, s.direction)))] += s.pixels;
    return rings;
}

WorkloadFrame WorkloadProbe::frame(int64_t index, double time_ms, const Pose& head,
                                   const Gaze& gaze, double count_to_deg) const {
    WorkloadFrame f;
    f.index = index;
    f.time_ms = time_ms;
    f.head = head;
    f.gaze = gaze;
    f.triangles_per_ring.assign(static_cast<size_t>(m_header.rings), 0.0);
    const glm::dvec3 gaze_eye = m_geometry.gazeDirection(gaze);
    const int rings = std::clamp(static_cast<int>(std::ceil(count_to_deg / m_header.ring_deg)) + 1,
                                 1, m_header.rings);
    for (Eye eye : {Eye::kLeft, Eye::kRight}) {
        if (m_clusters) {
            const RenderView view = fullFrameView(m_profile, head, eye);
            const Pose ep = eyePose(head, eye, CameraOptions{}.ipd_m);
            const glm::vec3 axis =
                glm::normalize(glm::normalize(ep.orientation) * glm::vec3(gaze_eye));
            addTrianglesPerRing(*m_clusters, view, m_lod_error_px, axis, m_header.ring_deg,
                                f.triangles_per_ring);
            continue;
        }
        const EyeView view = fullFrameEyeView(m_profile, head, eye);
        const std::vector<uint64_t> per_ring =
            m_bvh->trianglesPerRing(view, gaze_eye, m_header.ring_deg, rings);
        for (size_t k = 0; k < per_ring.size() && k < f.triangles_per_ring.size(); ++k)
            f.triangles_per_ring[k] += static_cast<double>(per_ring[k]);
    }
    f.pixels_per_ring = pixelsPerRing(gaze);
    f.bits_per_pixel.reserve(m_header.scales.size());
    for (double s : m_header.scales)
        f.bits_per_pixel.push_back(std::exp(m_log_bits_at_1) * std::pow(s, m_bits_exponent));
    return f;
}

void WorkloadProbe::observeBits(double middle_bytes, double middle_pixels, double s1,
                                double outer_bytes, double outer_pixels, double s2) {
    constexpr double kWeight = 0.5;
    const bool have_middle = middle_bytes > 0 && middle_pixels > 0;
    const bool have_outer = outer_bytes > 0 && outer_pixels > 0;
    if (have_middle && have_outer && s2 > s1 * 1.05) {
        const double bm = 8.0 * middle_bytes / middle_pixels;
        const double bo = 8.0 * outer_bytes / outer_pixels;
        const double gamma = std::clamp(std::log(bo / bm) / std::log(s2 / s1), -1.0, 3.0);
        m_bits_exponent = (1 - kWeight) * m_bits_exponent + kWeight * gamma;
    }
    if (have_middle || have_outer) {
        const double bytes = have_middle ? middle_bytes : outer_bytes;
        const double pixels = have_middle ? middle_pixels : outer_pixels;
        const double s = have_middle ? s1 : s2;
        const double log_b1 = std::log(8.0 * bytes / pixels) - m_bits_exponent * std::log(s);
        m_log_bits_at_1 = (1 - kWeight) * m_log_bits_at_1 + kWeight * log_b1;
    }
}

}  // namespace qvr::runtime
