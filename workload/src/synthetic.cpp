// Synthetic workloads (stand-ins for recorded levels). The world is a sphere of directions
// around the viewer holding a background of uniform triangle density plus dense objects; each
// frame the fovea's rings are integrated numerically in polar coordinates around the gaze, so
// triangles and shaded pixels per 1° ring follow from what the eye looks at — which is what
// makes T_local swing with motion, as in the paper's Fig. 5.
#include "qvr/workload/synthetic.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <glm/geometric.hpp>

namespace qvr {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRad = kPi / 180.0;
constexpr int kRings = 100;  // 1° rings out to 100°: beyond any corner of a 110° field
const std::vector<double> kScales = {1, 2, 4, 8, 16, 32};

struct WorldObject {
    glm::dvec3 direction;  // world frame, unit
    double sigma_rad;      // angular spread of its triangles
    double triangles;      // total
    double cos_cutoff;     // beyond 4σ it contributes nothing
};

struct HeadPath {
    double a1, f1, p1, a2, f2, p2;  // yaw = a1 sin(2π f1 t + p1) + a2 sin(2π f2 t + p2)
    double pitch_amp, pitch_f, pitch_p;
    double roll_amp, roll_f;

    EulerDeg at(double t_s) const {
        EulerDeg e;
        e.yaw_deg = a1 * std::sin(2 * kPi * f1 * t_s + p1) + a2 * std::sin(2 * kPi * f2 * t_s + p2);
        e.pitch_deg = pitch_amp * std::sin(2 * kPi * pitch_f * t_s + pitch_p);
        e.roll_deg = roll_amp * std::sin(2 * kPi * roll_f * t_s);
        return e;
    }
};

// A gaze that fixates, then saccades to a new target with a duration from the main sequence
// (Carpenter: about 21 ms + 2.2 ms per degree).
class GazeModel {
public:
    GazeModel(std::mt19937_64& rng, double fixation_ms, double radius_deg)
        : m_rng(rng), m_fixation_ms(fixation_ms), m_radius_deg(radius_deg) {
        m_next_saccade_ms = drawFixation();
    }

    Gaze at(double t_ms) {
        while (t_ms >= m_next_saccade_ms) {
            m_from = m_to;
            std::uniform_real_distribution<double> u(0.0, 1.0);
            const double r = m_radius_deg * std::sqrt(u(m_rng));
            const double a = 2 * kPi * u(m_rng);
            m_to = {std::clamp(r * std::cos(a), -30.0, 30.0),
                    std::clamp(0.8 * r * std::sin(a), -25.0, 25.0)};
            const double amp = std::hypot(m_to.x_deg - m_from.x_deg, m_to.y_deg - m_from.y_deg);
            m_saccade_start_ms = m_next_saccade_ms;
            m_saccade_ms = 21.0 + 2.2 * amp;
            m_next_saccade_ms = m_saccade_start_ms + m_saccade_ms + drawFixation();
        }
        const double s = std::clamp((t_ms - m_saccade_start_ms) / m_saccade_ms, 0.0, 1.0);
        return {m_from.x_deg + s * (m_to.x_deg - m_from.x_deg),
                m_from.y_deg + s * (m_to.y_deg - m_from.y_deg)};
    }

private:
    double drawFixation() {
        std::exponential_distribution<double> e(1.0 / std::max(1.0, m_fixation_ms - 100.0));
        return 100.0 + e(m_rng);
    }

    std::mt19937_64& m_rng;
    double m_fixation_ms;
    double m_radius_deg;
    Gaze m_from{}, m_to{};
    double m_saccade_start_ms = -1.0;
    double m_saccade_ms = 1.0;
    double m_next_saccade_ms = 0.0;
};

glm::dvec3 unitFromYawPitch(double yaw_deg, double pitch_deg) {
    const double y = yaw_deg * kRad;
    const double p = pitch_deg * kRad;
    return {-std::sin(y) * std::cos(p), std::sin(p), -std::cos(y) * std::cos(p)};
}

}  // namespace

SyntheticSpec defaultSyntheticSpec() {
    return SyntheticSpec{};
}

std::vector<SyntheticSpec> paperSyntheticSuite() {
    // Triangle counts scale with Table 3's draw batches (≈600 triangles a batch); coding cost
    // and head speed follow each genre (dark corridors compress well, racing turns fast).
    struct Row {
        const char* name;
        bool low_res;
        int batches;
        double bits;
        double head_speed;
        int objects;
    };
    const Row rows[] = {
        {"synthetic-doom3-h", false, 382, 0.45, 50, 16},
        {"synthetic-doom3-l", true, 382, 0.45, 50, 16},
        {"synthetic-hl2-h", false, 656, 0.55, 60, 20},
        {"synthetic-hl2-l", true, 656, 0.55, 60, 20},
        {"synthetic-grid", false, 3680, 0.80, 90, 32},
        {"synthetic-ut3", false, 1752, 0.65, 70, 28},
        {"synthetic-wolf", false, 3394, 0.70, 60, 32},
    };
    std::vector<SyntheticSpec> suite;
    uint64_t seed = 101;
    for (const Row& r : rows) {
        SyntheticSpec s;
        s.name = r.name;
        s.profile = r.low_res ? lowResHmdProfile() : defaultHmdProfile();
        s.seed = seed++;
        s.batches = r.batches;
        s.triangles_in_view = 600.0 * r.batches;
        s.bits_per_pixel_full = r.bits;
        s.head_peak_speed_deg_s = r.head_speed;
        s.objects = r.objects;
        suite.push_back(s);
    }
    return suite;
}

namespace {

// The random draws of one workload, in the order they are made (the same seed gives the same
// trace): one generator, and the distributions whose state carries over between draws.
struct Draws {
    std::mt19937_64 rng;
    std::uniform_real_distribution<double> uni{0.0, 1.0};
    std::normal_distribution<double> normal{0.0, 1.0};
    explicit Draws(uint64_t seed) : rng(seed) {}
};

// The sphere of directions around the viewer: a uniform background and dense objects.
struct World {
    double tan_h = 0.0, tan_v = 0.0;  // the field of view's half extents
    double bg_density = 0.0;          // triangles per steradian
    std::vector<WorldObject> objects;
};

WorkloadHeader syntheticHeader(const SyntheticSpec& spec) {
    WorkloadHeader h;
    h.name = spec.name;
    h.source = fmt::format("synthetic seed={} triangles_in_view={} objects={}", spec.seed,
                           spec.triangles_in_view, spec.objects);
    h.profile = spec.profile;
    h.ring_deg = 1.0;
    h.rings = kRings;
    h.scales = kScales;
    h.batches = spec.batches;
    return h;
}

World makeWorld(const SyntheticSpec& spec, Draws& draws) {
    World w;
    // The field of view's solid angle sets the density that puts triangles_in_view in view.
    w.tan_h = std::tan(0.5 * spec.profile.fov_h_deg * kRad);
    w.tan_v = std::tan(0.5 * spec.profile.fov_v_deg * kRad);
    const double fov_sr =
        4.0 * std::asin(std::sin(std::atan(w.tan_h)) * std::sin(std::atan(w.tan_v)));
    const double mean_density = spec.triangles_in_view / fov_sr;  // per steradian
    w.bg_density = (1.0 - spec.object_share) * mean_density;
    // Objects sit within ±40° of the horizon; their share is spread over that band.
    const double band_sr = 4.0 * kPi * std::sin(40.0 * kRad);
    const double object_total = spec.object_share * mean_density * band_sr;
    std::vector<double> weights;
    double weight_sum = 0.0;
    for (int i = 0; i < spec.objects; ++i) {
        weights.push_back(std::exp(0.8 * draws.normal(draws.rng)));
        weight_sum += weights.back();
    }
    for (int i = 0; i < spec.objects; ++i) {
        WorldObject o;
        const double yaw = 360.0 * draws.uni(draws.rng) - 180.0;
        const double pitch =
            std::asin((2.0 * draws.uni(draws.rng) - 1.0) * std::sin(40.0 * kRad)) / kRad;
        o.direction = unitFromYawPitch(yaw, pitch);
        const double radius_deg = spec.object_radius_deg * (0.5 + draws.uni(draws.rng));
        o.sigma_rad = 0.5 * radius_deg * kRad;
        o.triangles = object_total * weights[static_cast<size_t>(i)] / weight_sum;
        o.cos_cutoff = std::cos(std::min(4.0 * o.sigma_rad, kPi));
        w.objects.push_back(o);
    }
    return w;
}

// A head path scaled so that its peak yaw speed is the spec's.
HeadPath makeHeadPath(const SyntheticSpec& spec, Draws& draws) {
    auto& uni = draws.uni;
    auto& rng = draws.rng;
    HeadPath path{};
    path.a1 = 40.0;
    path.f1 = 0.08 + 0.06 * uni(rng);
    path.p1 = 2 * kPi * uni(rng);
    path.a2 = 8.0;
    path.f2 = 0.4 + 0.3 * uni(rng);
    path.p2 = 2 * kPi * uni(rng);
    const double peak = 2 * kPi * (path.a1 * path.f1 + path.a2 * path.f2);
    const double k = spec.head_peak_speed_deg_s / peak;
    path.a1 *= k;
    path.a2 *= k;
    path.pitch_amp = 6.0;
    path.pitch_f = 0.1 + 0.1 * uni(rng);
    path.pitch_p = 2 * kPi * uni(rng);
    path.roll_amp = 2.0;
    path.roll_f = 0.2;
    return path;
}

// Triangles and pixels each object puts in view this frame (one eye).
struct ObjectsInView {
    std::vector<glm::dvec3> eye_dirs;  // the objects' directions in eye space
    std::vector<double> triangles, pixels;
};

// The triangle density in eye-space direction d (one sample of solid angle d_omega covering
// `pixels`), charging each object its share.
double densityAt(const World& w, const glm::dvec3& d, double d_omega, double pixels,
                 ObjectsInView& in_view) {
    double density = w.bg_density;
    for (size_t i = 0; i < w.objects.size(); ++i) {
        const WorldObject& o = w.objects[i];
        const double c = glm::dot(d, in_view.eye_dirs[i]);
        if (c < o.cos_cutoff)
            continue;
        const double theta = std::acos(std::min(1.0, c));
        const double s2 = o.sigma_rad * o.sigma_rad;
        const double od = o.triangles * std::exp(-0.5 * theta * theta / s2) / (2 * kPi * s2);
        density += od;
        in_view.triangles[i] += od * d_omega;
        if (theta < 2.0 * o.sigma_rad)
            in_view.pixels[i] += pixels;
    }
    return density;
}

// Integrates the frame's 1° rings around the gaze in polar coordinates: triangles and shaded
// pixels per ring, both eyes.
void integrateRings(const World& w, const SyntheticSpec& spec, WorkloadFrame& f,
                    ObjectsInView& in_view) {
    const double fx = spec.profile.focalXPx();
    const double fy = spec.profile.focalYPx();
    const glm::dvec3 g = glm::normalize(
        glm::dvec3(std::tan(f.gaze.x_deg * kRad), std::tan(f.gaze.y_deg * kRad), -1.0));
    const glm::dvec3 helper = std::fabs(g.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, g));
    const glm::dvec3 v = glm::cross(g, u);
    f.triangles_per_ring.assign(kRings, 0.0);
    f.pixels_per_ring.assign(kRings, 0.0);
    for (int ring = 0; ring < kRings; ++ring) {
        // Finer radial sampling near the gaze where the rings are small.
        const int n_r = ring < 10 ? 4 : 1;
        const double de = kRad / n_r;
        for (int ir = 0; ir < n_r; ++ir) {
            const double e = (ring + (ir + 0.5) / n_r) * kRad;
            const double se = std::sin(e), ce = std::cos(e);
            const int n_phi = std::max(8, static_cast<int>(std::ceil(se * 360.0 / 1.5)));
            const double dphi = 2 * kPi / n_phi;
            const double d_omega = se * de * dphi;
            for (int ip = 0; ip < n_phi; ++ip) {
                const double phi = (ip + 0.5) * dphi;
                const glm::dvec3 d = ce * g + se * (std::cos(phi) * u + std::sin(phi) * v);
                if (d.z >= -1e-6)
                    continue;
                const double X = d.x / -d.z;
                const double Y = d.y / -d.z;
                if (std::fabs(X) > w.tan_h || std::fabs(Y) > w.tan_v)
                    continue;
                const double r2 = 1.0 + X * X + Y * Y;
                const double pixels = d_omega * fx * fy * r2 * std::sqrt(r2);
                const double density = densityAt(w, d, d_omega, pixels, in_view);
                f.triangles_per_ring[static_cast<size_t>(ring)] += 2.0 * density * d_omega;
                f.pixels_per_ring[static_cast<size_t>(ring)] += 2.0 * pixels;
            }
        }
    }
}

// Static design: the object with the most triangles in view is the "nearest batch".
void splitStatic(const SyntheticSpec& spec, const ObjectsInView& in_view, WorkloadFrame& f) {
    const double full_pixels_both = 2.0 * spec.profile.width_px * spec.profile.height_px;
    size_t fg = 0;
    for (size_t i = 1; i < in_view.triangles.size(); ++i)
        if (in_view.triangles[i] > in_view.triangles[fg])
            fg = i;
    const double total_pixels = sumTotal(f.pixels_per_ring);
    if (!in_view.triangles.empty()) {
        f.static_split.fg_triangles = 2.0 * in_view.triangles[fg];
        f.static_split.fg_screen_fraction =
            total_pixels > 0 ? std::min(1.0, 2.0 * in_view.pixels[fg] / total_pixels) : 0.0;
    }
    f.static_split.bg_bytes = full_pixels_both * f.bits_per_pixel.front() / 8.0;
    f.static_split.depth_bytes = full_pixels_both * spec.depth_bits_per_pixel / 8.0;
}

}  // namespace

WorkloadTrace generateSyntheticWorkload(const SyntheticSpec& spec) {
    QVR_CHECK(spec.frames >= 0 && spec.frames <= kMaxTraceFrames);
    QVR_CHECK(spec.objects >= 0 && spec.objects <= 10000);
    Draws draws(spec.seed);
    WorkloadTrace trace;
    trace.header = syntheticHeader(spec);
    const World world = makeWorld(spec, draws);
    const HeadPath path = makeHeadPath(spec, draws);
    const double detail_phase = 2 * kPi * draws.uni(draws.rng);
    GazeModel gaze_model(draws.rng, spec.fixation_ms, spec.saccade_radius_deg);
    const double frame_ms = 1000.0 / spec.profile.refresh_hz;

    EulerDeg previous_euler = path.at(-frame_ms / 1000.0);
    trace.frames.reserve(static_cast<size_t>(spec.frames));
    for (int n = 0; n < spec.frames; ++n) {
        WorkloadFrame f;
        f.index = n;
        f.time_ms = n * frame_ms;
        const double t_s = f.time_ms / 1000.0;
        const EulerDeg euler = path.at(t_s);
        f.head.orientation = quatFromEulerDeg(euler);
        f.head.position_m =
            glm::vec3(static_cast<float>(0.05 * std::sin(2 * kPi * 0.3 * t_s)), 1.7f,
                      static_cast<float>(0.03 * std::sin(2 * kPi * 0.2 * t_s)));
        f.gaze = gaze_model.at(f.time_ms);

        // Rotate world objects into eye space once per frame.
        const glm::dquat to_eye = glm::inverse(glm::dquat(f.head.orientation));
        ObjectsInView in_view;
        in_view.eye_dirs.reserve(world.objects.size());
        for (const auto& o : world.objects)
            in_view.eye_dirs.push_back(to_eye * o.direction);
        in_view.triangles.assign(world.objects.size(), 0.0);
        in_view.pixels.assign(world.objects.size(), 0.0);
        integrateRings(world, spec, f, in_view);

        // Periphery coding cost: more bits per pixel at coarser scales, under faster head
        // motion (less temporal prediction), and where the scenery is busier.
        const double speed_deg_s = std::hypot(euler.yaw_deg - previous_euler.yaw_deg,
                                              euler.pitch_deg - previous_euler.pitch_deg) /
                                   (frame_ms / 1000.0);
        previous_euler = euler;
        const double detail = 1.0 + 0.2 * std::sin(2.0 * euler.yaw_deg * kRad + detail_phase);
        const double noise = std::exp(0.03 * draws.normal(draws.rng));
        const double motion = 1.0 + spec.motion_bits_gain * speed_deg_s / 100.0;
        f.bits_per_pixel.clear();
        for (double s : kScales) {
            f.bits_per_pixel.push_back(spec.bits_per_pixel_full *
                                       std::pow(s, spec.bits_scale_exponent) * motion * detail *
                                       noise);
        }
        splitStatic(spec, in_view, f);
        trace.frames.push_back(std::move(f));
    }
    QVR_CHECK(validateTrace(trace).ok());
    return trace;
}

}  // namespace qvr
