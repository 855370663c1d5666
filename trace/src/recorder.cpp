// The workload recorder: each frame renders both eyes' full frames with the real renderer,
// encodes them at every layer scale as persistent x264 streams, counts triangles per ring with
// the scene's BVH and shaded pixels per ring with a CPU z-buffer, and writes one flushed line.
// Choices and their costs are in docs/RECORDING.md.
#include "qvr/trace/recorder.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "qvr/foveation/eye_geometry.h"
#include "qvr/render/camera.h"
#include "qvr/render/renderer.h"
#include "qvr/scene/triangle_bvh.h"
#include "qvr/trace/depth_raster.h"
#include "qvr/trace/head_motion.h"
#include "qvr/workload/trace_io.h"

namespace qvr {

namespace {

constexpr double kPi = 3.14159265358979323846;

bool endsWithNoCase(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size())
        return false;
    return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
        return std::tolower(static_cast<unsigned char>(a)) ==
               std::tolower(static_cast<unsigned char>(b));
    });
}

// Numbers are rounded before writing so a 300-frame trace stays a few hundred kilobytes: the
// measurements are not more precise than this anyway (x264 sizes vary by more run to run).
double roundTo(double v, double step) {
    return std::round(v / step) * step;
}
double roundSignificant(double v, int digits) {
    if (v == 0.0 || !std::isfinite(v))
        return v;
    const double mag =
        std::pow(10.0, digits - 1 - static_cast<int>(std::floor(std::log10(std::fabs(v)))));
    return std::round(v * mag) / mag;
}

bool isPowerOfTwo(double s) {
    if (s < 1.0 || s > 1024.0 || s != std::floor(s))
        return false;
    const auto i = static_cast<unsigned>(s);
    return (i & (i - 1)) == 0;
}

Status checkOptions(const RecordOptions& o) {
    if (o.frames < 1 || o.frames > 1'000'000)
        return makeError(fmt::format("--frames must be in 1..1000000, got {}", o.frames));
    if (o.spawn < 0)
        return makeError(fmt::format("--spawn must be >= 0, got {}", o.spawn));
    if (o.scales.empty() || o.scales.front() != 1.0)
        return makeError(
            "the scales must start at 1 (the static design's background is the "
            "scale-1 stream)");
    for (size_t i = 0; i < o.scales.size(); ++i) {
        if (!isPowerOfTwo(o.scales[i]) || (i > 0 && o.scales[i] <= o.scales[i - 1]))
            return makeError(fmt::format(
                "scales must be increasing powers of two up to 1024 (each is a box-halving of "
                "the one before), got {}",
                o.scales[i]));
    }
    if (o.raster_scale < 1 || o.raster_scale > 16)
        return makeError(fmt::format("raster scale must be in 1..16, got {}", o.raster_scale));
    if (!(o.ring_deg > 0.0) || o.rings < 1 || o.rings > kMaxRings || o.ring_deg * o.rings < 45.0 ||
        o.ring_deg * o.rings > 180.0)
        return makeError("rings must cover 45..180 degrees (docs/WORKLOAD_FORMAT.md)");
    if (o.foreground_objects < 0)
        return makeError("foreground objects must be >= 0");
    return {};
}

Expected<PoseTrace> loadMotion(const RecordOptions& o, std::string& source) {
    const double rate_hz = o.profile.refresh_hz;
    if (o.motion == "default" || endsWithNoCase(o.motion, ".bvh")) {
        const std::string path = o.motion == "default" ? defaultBvhPath() : o.motion;
        auto bvh = loadBvhFile(path);
        if (!bvh)
            return makeError(fmt::format(
                "motion: {}{}", bvh.error(),
                o.motion == "default" ? " (install the Debian package assimp-testmodels)" : ""));
        HeadMotionOptions h;
        h.rate_hz = rate_hz;
        h.frames = o.frames;
        auto trace = headTraceFromBvh(*bvh, h);
        if (!trace)
            return makeError(fmt::format("motion: {}: {}", path, trace.error()));
        source = path;
        return trace;
    }
    auto csv = loadPoseCsv(o.motion);
    if (!csv)
        return makeError(fmt::format("motion: {}", csv.error()));
    auto trace = resamplePoses(*csv, rate_hz, o.frames);
    if (!trace)
        return makeError(fmt::format("motion: {}: {}", o.motion, trace.error()));
    source = o.motion;
    return trace;
}

}  // namespace

Expected<RecordInputs> prepareRecording(const RecordOptions& options) {
    if (Status s = checkOptions(options); !s)
        return makeError(s.error());
    RecordInputs in;
    auto motion = loadMotion(options, in.motion_source);
    if (!motion)
        return makeError(motion.error());
    if (static_cast<int>(motion->samples.size()) < options.frames)
        return makeError(fmt::format("motion: {} holds {} frames at {} Hz, {} asked for",
                                     options.motion, motion->samples.size(),
                                     options.profile.refresh_hz, options.frames));
    if (options.gaze_csv.empty()) {
        const double duration_ms = options.frames * 1000.0 / options.profile.refresh_hz;
        const GazeModelConfig config;
        const int samples =
            static_cast<int>(std::ceil(duration_ms * config.sample_rate_hz / 1000.0)) + 2;
        auto gaze = generateGaze(config, options.gaze_seed, samples);
        if (!gaze)
            return makeError(fmt::format("gaze: {}", gaze.error()));
        in.gaze = std::move(*gaze);
        in.gaze_source = fmt::format("model seed {}", options.gaze_seed);
    } else {
        auto gaze = loadGazeCsv(options.gaze_csv);
        if (!gaze)
            return makeError(fmt::format("gaze: {}", gaze.error()));
        in.gaze = std::move(*gaze);
        in.gaze_source = options.gaze_csv;
    }
    auto scene = loadScene(options.scene, options.scene_options, &in.report);
    if (!scene)
        return makeError(fmt::format("scene: {}", scene.error()));
    in.scene = std::move(*scene);
    if (options.spawn >= static_cast<int>(in.scene.spawns.size()))
        return makeError(fmt::format("--spawn {}: {} has {} spawn point(s)", options.spawn,
                                     in.scene.name, in.scene.spawns.size()));
    // The trace's first eye position goes to the spawn point's eye, its heading to the spawn's.
    const SpawnPoint& spawn = in.scene.spawns[static_cast<size_t>(options.spawn)];
    const float first_y = motion->samples.front().pose.position_m.y;
    motion->samples.resize(static_cast<size_t>(options.frames));
    in.poses = placePoses(
        *motion, glm::vec3(spawn.position_m.x, spawn.position_m.y - first_y, spawn.position_m.z),
        spawn.yaw_deg);
    return in;
}

namespace {

// Byte and pixel counts of one frame's streams, both eyes summed.
struct FrameSizes {
    std::vector<double> bytes, pixels, lossless_bytes;  // per scale
    double depth_bytes = 0.0;
    explicit FrameSizes(size_t n_scales)
        : bytes(n_scales, 0.0), pixels(n_scales, 0.0), lossless_bytes(n_scales, 0.0) {}
};

// What the recording keeps from frame to frame: the scene's counters, the persistent encoder
// streams, the raster grid and the scratch images.
class Recording {
public:
    Recording(const RecordOptions& options, const RecordInputs& inputs, Renderer& renderer)
        : m_options(options),
          m_inputs(inputs),
          m_profile(options.profile),
          m_renderer(renderer),
          m_bvh(inputs.scene),
          m_rasterizer(inputs.scene, options.object_cell_m),
          m_geometry(options.profile),
          m_codec(options.codec) {
        m_codec.frame_rate_hz = m_profile.refresh_hz;
        markObjects();
        layOutRaster();
    }

    Status openEncoders();
    WorkloadHeader header() const;
    Expected<WorkloadFrame> frame(int n);

private:
    void markObjects();
    void layOutRaster();
    void assignRings(const glm::dvec3& gaze_dir);
    Status recordEye(int n, int e, const Pose& head, const glm::dvec3& gaze_dir, WorkloadFrame& f,
                     FrameSizes& sizes);
    Status encodeScales(int n, int e, FrameSizes& sizes);
    Status rasterizeEye(int n, int e, const RenderView& view, WorkloadFrame& f, FrameSizes& sizes);
    void splitStatic(const Pose& head, WorkloadFrame& f) const;

    const RecordOptions& m_options;
    const RecordInputs& m_inputs;
    const HmdProfile& m_profile;
    Renderer& m_renderer;
    const TriangleBvh m_bvh;
    const DepthRasterizer m_rasterizer;
    const EyeGeometry m_geometry;
    CodecConfig m_codec;
    std::vector<bool> m_flat;          // per object: architecture, not an interactive object
    std::vector<bool> m_interactive;   // per object: part of an interactive batch
    bool m_marks_interactive = false;  // the scene marks its interactive batches
    // Persistent streams, so P-frames predict from the previous frame as they would on the wire.
    std::array<std::vector<std::unique_ptr<VideoEncoder>>, 2> m_colour_enc;
    std::array<std::vector<std::unique_ptr<VideoEncoder>>, 2> m_lossless_enc;
    std::array<std::array<std::unique_ptr<VideoEncoder>, 2>, 2> m_depth_enc;
    // Each raster pixel's view direction, how many full-resolution pixels it stands for and its
    // ring around this frame's gaze.
    std::vector<glm::dvec3> m_directions;
    std::vector<float> m_weights;
    std::vector<int> m_ring_of;
    ImageRgba8 m_full, m_halved, m_depth_high, m_depth_low;
    std::array<DepthRaster, 2> m_rasters;
};

void Recording::markObjects() {
    const auto n = static_cast<size_t>(m_rasterizer.objectCount());
    m_flat.resize(n);
    m_interactive.resize(n);
    for (int id = 0; id < m_rasterizer.objectCount(); ++id) {
        const Aabb& b = m_rasterizer.objectBounds(id);
        const glm::vec3 size = b.max - b.min;
        const auto i = static_cast<size_t>(id);
        m_flat[i] =
            std::min({size.x, size.y, size.z}) < static_cast<float>(m_options.flat_object_m);
        m_interactive[i] =
            m_inputs.scene.batches[static_cast<size_t>(m_rasterizer.objectBatch(id))].interactive;
        m_marks_interactive = m_marks_interactive || m_interactive[i];
    }
}

void Recording::layOutRaster() {
    const int r = m_options.raster_scale;
    const int rw = (m_profile.width_px + r - 1) / r;
    const int rh = (m_profile.height_px + r - 1) / r;
    m_directions.resize(static_cast<size_t>(rw) * static_cast<size_t>(rh));
    m_weights.resize(m_directions.size());
    m_ring_of.resize(m_directions.size());
    for (int y = 0; y < rh; ++y) {
        for (int x = 0; x < rw; ++x) {
            const size_t p = static_cast<size_t>(y) * rw + x;
            const int cw = std::min(r, m_profile.width_px - x * r);
            const int ch = std::min(r, m_profile.height_px - y * r);
            m_directions[p] = m_geometry.directionAt(x * r + 0.5 * cw, y * r + 0.5 * ch);
            m_weights[p] = static_cast<float>(cw * ch);
        }
    }
}

Status Recording::openEncoders() {
    CodecConfig lossless = m_codec;
    lossless.crf = 0;
    for (size_t eye = 0; eye < 2; ++eye) {
        for (size_t s = 0; s < m_options.scales.size(); ++s) {
            auto e = makeVideoEncoder(m_codec);
            if (!e)
                return makeError(fmt::format("encoder: {}", e.error()));
            m_colour_enc[eye].push_back(std::move(*e));
            if (m_options.record_lossless) {
                auto l = makeVideoEncoder(lossless);
                if (!l)
                    return makeError(fmt::format("lossless encoder: {}", l.error()));
                m_lossless_enc[eye].push_back(std::move(*l));
            }
        }
        for (size_t p = 0; p < 2; ++p) {
            auto e = makeVideoEncoder(m_codec);
            if (!e)
                return makeError(fmt::format("encoder: {}", e.error()));
            m_depth_enc[eye][p] = std::move(*e);
        }
    }
    return {};
}

WorkloadHeader Recording::header() const {
    const Scene& scene = m_inputs.scene;
    const int r = m_options.raster_scale;
    WorkloadHeader h;
    h.name = m_options.name.empty() ? scene.name : m_options.name;
    h.source = fmt::format(
        "recorded {} spawn {} by {}; motion {}; gaze {}; tri: BVH frustum counts per ring, both "
        "eyes; pix: fragments passing an early depth test in draw order, both faces (CPU z-buffer "
        "at 1/{} resolution); bpp: x264 {} crf {} keyint {}, one stream per eye and scale, the "
        "full frame box-halved from the scale-1 render, 24-byte frame headers included; "
        "bpp_lossless: {}the same streams at crf 0 (x264 lossless, the paper's setting); static: "
        "fg = {} (batch x {} m cells), bg = the scale-1 frame, depth = 16 bits as two 8-bit "
        "planes (high, folded low) at 1/{} resolution",
        scene.name, m_options.spawn, m_renderer.name(), m_inputs.motion_source,
        m_inputs.gaze_source, r, m_codec.preset, m_codec.crf, m_codec.keyint_frames,
        m_options.record_lossless ? "" : "not recorded; ",
        m_marks_interactive
            ? std::string("every visible object of the interactive batches (items, pieces)")
            : fmt::format("nearest {} visible non-flat objects by bounds distance",
                          m_options.foreground_objects),
        m_options.object_cell_m, r);
    h.profile = m_profile;
    h.ring_deg = m_options.ring_deg;
    h.rings = m_options.rings;
    h.scales = m_options.scales;
    h.batches = static_cast<int>(scene.batches.size());
    return h;
}

void Recording::assignRings(const glm::dvec3& gaze_dir) {
    for (size_t p = 0; p < m_directions.size(); ++p) {
        const double e_deg =
            std::acos(std::clamp(glm::dot(m_directions[p], gaze_dir), -1.0, 1.0)) * 180.0 / kPi;
        m_ring_of[p] = std::min(m_options.rings - 1, static_cast<int>(e_deg / m_options.ring_deg));
    }
}

// Scale 1, 2, 4, …: each a box-halving of the one before (what a layer rendered at that scale
// shows, up to filtering: docs/RECORDING.md), encoded on its own stream.
Status Recording::encodeScales(int n, int e, FrameSizes& sizes) {
    const size_t n_scales = m_options.scales.size();
    const double max_scale = m_options.scales.back();
    const ImageRgba8* current = &m_full;
    size_t next = 0;
    for (double s = 1.0; s <= max_scale && next < n_scales; s *= 2.0) {
        if (s > 1.0) {
            halveImage(*current, m_halved);
            std::swap(m_full, m_halved);
            current = &m_full;
        }
        if (s != m_options.scales[next])
            continue;
        auto encoded = m_colour_enc[static_cast<size_t>(e)][next]->encode(*current);
        if (!encoded)
            return makeError(
                fmt::format("frame {}: encode at scale {}: {}", n, s, encoded.error()));
        sizes.bytes[next] += static_cast<double>(encoded->bytes.size());
        if (m_options.record_lossless) {
            auto exact = m_lossless_enc[static_cast<size_t>(e)][next]->encode(*current);
            if (!exact)
                return makeError(
                    fmt::format("frame {}: lossless encode at scale {}: {}", n, s, exact.error()));
            sizes.lossless_bytes[next] += static_cast<double>(exact->bytes.size());
        }
        sizes.pixels[next] += static_cast<double>(current->width()) * current->height();
        ++next;
    }
    return {};
}

// The eye's shaded pixels per ring and its depth planes' bytes.
Status Recording::rasterizeEye(int n, int e, const RenderView& view, WorkloadFrame& f,
                               FrameSizes& sizes) {
    DepthRaster& raster = m_rasters[static_cast<size_t>(e)];
    m_rasterizer.rasterize(view.view, view.projection, m_profile.width_px, m_profile.height_px,
                           m_options.raster_scale, raster);
    for (size_t p = 0; p < m_directions.size(); ++p) {
        if (raster.shaded[p] != 0)
            f.pixels_per_ring[static_cast<size_t>(m_ring_of[p])] +=
                static_cast<double>(raster.shaded[p]) * m_weights[p];
    }
    depthPlanes(raster, m_depth_high, m_depth_low);
    for (size_t plane = 0; plane < 2; ++plane) {
        auto encoded = m_depth_enc[static_cast<size_t>(e)][plane]->encode(plane == 0 ? m_depth_high
                                                                                     : m_depth_low);
        if (!encoded)
            return makeError(fmt::format("frame {}: depth encode: {}", n, encoded.error()));
        sizes.depth_bytes += static_cast<double>(encoded->bytes.size());
    }
    return {};
}

Status Recording::recordEye(int n, int e, const Pose& head, const glm::dvec3& gaze_dir,
                            WorkloadFrame& f, FrameSizes& sizes) {
    const Eye eye = e == 0 ? Eye::kLeft : Eye::kRight;
    const auto rings = m_bvh.trianglesPerRing(fullFrameEyeView(m_profile, head, eye), gaze_dir,
                                              m_options.ring_deg, m_options.rings);
    for (size_t k = 0; k < rings.size(); ++k)
        f.triangles_per_ring[k] += static_cast<double>(rings[k]);
    const RenderView view = fullFrameView(m_profile, head, eye);
    auto stats = m_renderer.render(view, m_full);
    if (!stats)
        return makeError(fmt::format("frame {}: render: {}", n, stats.error()));
    if (Status s = encodeScales(n, e, sizes); !s)
        return s;
    return rasterizeEye(n, e, view, f, sizes);
}

// The static design's foreground (§2, Table 1: the interactive objects, rendered locally): every
// visible object of the scene's interactive batches. A scene that marks none falls back to §6.1's
// reading, the visible objects nearest the head by bounds distance; flat pieces (floor, wall and
// ceiling cells) are architecture, without this rule the floor under the viewer would always win.
void Recording::splitStatic(const Pose& head, WorkloadFrame& f) const {
    std::vector<int> visible;
    for (int id = 0; id < m_rasterizer.objectCount(); ++id) {
        const auto i = static_cast<size_t>(id);
        const bool candidate = m_marks_interactive ? m_interactive[i] : !m_flat[i];
        if (candidate && m_rasters[0].object_pixels[i] + m_rasters[1].object_pixels[i] > 0)
            visible.push_back(id);
    }
    size_t k = visible.size();
    if (!m_marks_interactive) {
        k = std::min(k, static_cast<size_t>(m_options.foreground_objects));
        std::partial_sort(visible.begin(), visible.begin() + static_cast<std::ptrdiff_t>(k),
                          visible.end(), [&](int a, int b) {
                              return distanceToBox(head.position_m, m_rasterizer.objectBounds(a)) <
                                     distanceToBox(head.position_m, m_rasterizer.objectBounds(b));
                          });
    }
    double fg_triangles = 0.0, fg_pixels = 0.0;
    for (size_t i = 0; i < k; ++i) {
        for (const DepthRaster& raster : m_rasters) {
            fg_triangles += raster.object_triangles[static_cast<size_t>(visible[i])];
            fg_pixels += raster.object_pixels[static_cast<size_t>(visible[i])];
        }
    }
    const int r = m_options.raster_scale;
    const double frame_pixels = 2.0 * m_profile.width_px * m_profile.height_px;
    f.static_split.fg_triangles = fg_triangles;
    f.static_split.fg_screen_fraction =
        roundSignificant(std::min(1.0, fg_pixels * r * r / frame_pixels), 4);
}

Expected<WorkloadFrame> Recording::frame(int n) {
    const size_t n_scales = m_options.scales.size();
    const double frame_ms = 1000.0 / m_profile.refresh_hz;
    WorkloadFrame f;
    f.index = n;
    f.time_ms = roundTo(n * frame_ms, 1e-3);
    const Pose head = m_inputs.poses.samples[static_cast<size_t>(n)].pose;
    f.gaze = gazeAt(m_inputs.gaze, n * frame_ms);
    f.gaze.x_deg = roundTo(f.gaze.x_deg, 1e-3);
    f.gaze.y_deg = roundTo(f.gaze.y_deg, 1e-3);
    const glm::dvec3 gaze_dir = m_geometry.gazeDirection(f.gaze);
    f.triangles_per_ring.assign(static_cast<size_t>(m_options.rings), 0.0);
    f.pixels_per_ring.assign(static_cast<size_t>(m_options.rings), 0.0);
    FrameSizes sizes(n_scales);
    assignRings(gaze_dir);
    for (int e = 0; e < 2; ++e)
        if (Status s = recordEye(n, e, head, gaze_dir, f, sizes); !s)
            return makeError(s.error());
    for (double& v : f.pixels_per_ring)
        v = std::round(v);
    for (size_t s = 0; s < n_scales; ++s)
        f.bits_per_pixel.push_back(roundSignificant(sizes.bytes[s] * 8.0 / sizes.pixels[s], 4));
    if (m_options.record_lossless) {
        for (size_t s = 0; s < n_scales; ++s)
            f.bits_per_pixel_lossless.push_back(
                roundSignificant(sizes.lossless_bytes[s] * 8.0 / sizes.pixels[s], 4));
        f.static_split.bg_bytes_lossless = sizes.lossless_bytes[0];
    }
    splitStatic(head, f);
    f.static_split.bg_bytes = sizes.bytes[0];
    f.static_split.depth_bytes = sizes.depth_bytes;
    f.head.orientation = head.orientation;
    for (int c = 0; c < 4; ++c)
        f.head.orientation[c] = static_cast<float>(roundTo(head.orientation[c], 1e-5));
    for (int c = 0; c < 3; ++c)
        f.head.position_m[c] = static_cast<float>(roundTo(head.position_m[c], 1e-4));
    return f;
}

}  // namespace

Expected<RecordResult> recordWorkload(const RecordOptions& options, const RecordInputs& inputs,
                                      Renderer& renderer, std::ostream& out,
                                      const std::atomic<bool>* stop,
                                      const std::function<void(const RecordProgress&)>& progress) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    if (Status s = checkOptions(options); !s)
        return makeError(s.error());
    if (static_cast<int>(inputs.poses.samples.size()) < options.frames)
        return makeError("fewer poses than frames");
    if (Status s = renderer.upload(inputs.scene); !s)
        return makeError(fmt::format("upload of {}: {}", inputs.scene.name, s.error()));
    Recording recording(options, inputs, renderer);
    if (Status s = recording.openEncoders(); !s)
        return makeError(s.error());

    RecordResult result;
    result.header = recording.header();
    WorkloadTraceWriter writer(out);
    writer.writeHeader(result.header);
    if (!out)
        return makeError("cannot write the trace header");
    for (int n = 0; n < options.frames; ++n) {
        if (stop != nullptr && stop->load()) {
            result.stopped = true;
            break;
        }
        const auto frame_start = Clock::now();
        auto f = recording.frame(n);
        if (!f)
            return makeError(f.error());
        // The line must pass the reader's checks before it is written.
        WorkloadTrace one;
        one.header = result.header;
        one.frames.push_back(*f);
        if (Status s = validateTrace(one); !s)
            return makeError(fmt::format("frame {}: {}", n, s.error()));
        writer.writeFrame(*f);
        if (!out)
            return makeError(fmt::format("frame {}: write failed", n));
        ++result.frames_written;
        if (progress) {
            RecordProgress p;
            p.frame = result.frames_written;
            p.frames = options.frames;
            p.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
            p.last_frame_s = std::chrono::duration<double>(Clock::now() - frame_start).count();
            progress(p);
        }
    }
    result.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
}

}  // namespace qvr
