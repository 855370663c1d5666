// UCA orchestration (paper §4.2, Eq. 3–4): validates a layer frame, turns plan and poses into
// kernel parameters, classifies the 32×32 tiles once per frame, runs them in parallel; frame
// reuse for late layers; the two-pass reference built from the same kernel.
#include "qvr/compose/uca.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "qvr/compose/warp.h"
#include "qvr/foveation/eye_geometry.h"
#include "uca_kernel.h"

namespace qvr {

namespace detail {
// The map at the tile corners, shared by the four tiles that meet there: the rendered-image
// point, the unit direction and its eccentricity, per chroma scale in use.
struct CornerSample {
    double px = 0, py = 0;
    double ux = 0, uy = 0, uz = 0;
    double e_deg = 0;
    bool in_front = false;
};

}  // namespace detail

namespace {

using detail::CornerSample;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();
// A hard layer edge still gets a ramp this wide so the weights stay finite.
constexpr double kMinBandDeg = 1e-3;
// The kernel forms texel indices in float, exact below 2^24.
constexpr int64_t kMaxTexels = int64_t{1} << 24;

const char* kLayerNames[3] = {"fovea", "middle", "outer"};

const ImageRgba8& layerImage(const EyeLayerImages& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}
const LayerRect& layerRect(const EyeLayers& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}

using detail::SlotInfo;

SlotInfo slotsOf(const HmdProfile& profile, const LayerPlan& plan, int eye, double band_texels) {
    SlotInfo s;
    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
    const double radius[3] = {plan.e1_deg, plan.e2_deg, kInf};
    for (int k = 0; k < 3; ++k) {
        if (layerRect(layers, k).empty())
            continue;
        s.layer[s.count] = k;
        s.radius_deg[s.count] = radius[k];
        ++s.count;
    }
    s.radius_deg[s.count - 1] = kInf;  // the outermost present layer covers the rest
    for (int k = 0; k + 1 < s.count; ++k) {
        // Eq. 4's blend band: a few texels of the coarser layer, inside the finer one's disc
        // (where both layers hold rendered pixels) and never reaching the previous border.
        const double coarse_scale = layerRect(layers, s.layer[k + 1]).scale;
        double band = band_texels * coarse_scale * profile.pixelAngleDeg();
        const double inner = k == 0 ? 0.0 : s.radius_deg[k - 1];
        band = std::min(band, s.radius_deg[k] - inner);
        s.band_deg[k] = std::max(band, kMinBandDeg);
    }
    return s;
}

detail::KernelLayer kernelLayer(const ImageRgba8& image, const LayerRect& rect) {
    detail::KernelLayer l;
    l.texels = image.data();
    l.width = image.width();
    l.height = image.height();
    const double inv = 1.0 / rect.scale;
    l.inv_scale = static_cast<float>(inv);
    l.offset_x = static_cast<float>(-rect.rect.x0 * inv - 0.5);
    l.offset_y = static_cast<float>(-rect.rect.y0 * inv - 0.5);
    return l;
}

void setWarpParams(detail::KernelParams& p, const EyeWarp& warp, const Gaze& gaze,
                   bool chroma_enabled) {
    p.ax = static_cast<float>(1.0 / warp.fx());
    p.bx = static_cast<float>((0.5 - warp.cx()) / warp.fx());
    p.ay = static_cast<float>(-1.0 / warp.fy());
    p.by = static_cast<float>(-(0.5 - warp.cy()) / warp.fy());
    p.k1 = static_cast<float>(warp.lens().k1);
    p.k2 = static_cast<float>(warp.lens().k2);
    p.chroma_red = static_cast<float>(warp.lens().chroma_red_scale);
    p.chroma_blue = static_cast<float>(warp.lens().chroma_blue_scale);
    p.chroma = chroma_enabled && (p.chroma_red != 1.0f || p.chroma_blue != 1.0f);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            p.m[r * 3 + c] = static_cast<float>(warp.rotation()[c][r]);
    }
    p.fx = static_cast<float>(warp.fx());
    p.fy = static_cast<float>(warp.fy());
    p.cx = static_cast<float>(warp.cx());
    p.cy = static_cast<float>(warp.cy());
    p.width = static_cast<float>(warp.width());
    p.height = static_cast<float>(warp.height());
    const glm::dvec3 g = glm::normalize(
        glm::dvec3(std::tan(gaze.x_deg / kDegPerRad), std::tan(gaze.y_deg / kDegPerRad), -1.0));
    p.gaze[0] = static_cast<float>(g.x);
    p.gaze[1] = static_cast<float>(g.y);
    p.gaze[2] = static_cast<float>(g.z);
}

void setBorders(detail::KernelParams& p, const SlotInfo& s) {
    for (int k = 0; k < 2; ++k) {
        p.border_c_hi[k] = 2.0f;
        p.border_inv[k] = 0.0f;
        if (k + 1 >= s.count)
            continue;
        const double c_hi = std::cos((s.radius_deg[k] - s.band_deg[k]) / kDegPerRad);
        const double c_lo = std::cos(s.radius_deg[k] / kDegPerRad);
        p.border_c_hi[k] = static_cast<float>(c_hi);
        p.border_inv[k] = static_cast<float>(1.0 / (c_hi - c_lo));
    }
}

// One eye of one pass: the map, the kernel parameters and the slots for classification.
struct EyeJob {
    EyeWarp warp;
    SlotInfo slots;
    detail::KernelParams params;
    ImageRgba8* out = nullptr;
    std::vector<TileKind>* kinds = nullptr;
    std::vector<uint8_t>* masks = nullptr;
    // The display image streams past the caches; the two-pass eye buffer, read right back by
    // its second pass, does not.
    bool stream_output = true;
    // UCA may interpolate its map on the mesh where the error bound holds (docs/UCA.md, "Mesh
    // tiles"); the two-pass reference maps every pixel exactly, so the quality bar it sets
    // does not move.
    bool mesh = false;
    // Stream the layers into the caches before the tiles gather from them (UCA; the two-pass
    // passes read their inputs back warm or are the eye buffer itself).
    bool prefetch_layers = false;
};

// Points the job's kernel at one eye's layer images, slot by slot, with their blend borders.
void bindLayers(EyeJob& j, const LayerFrame& frame, int eye) {
    j.params.slot_count = j.slots.count;
    for (int k = 0; k < j.slots.count; ++k) {
        const int layer = j.slots.layer[k];
        j.params.slots[k] =
            kernelLayer(layerImage(frame.eyes[static_cast<size_t>(eye)], layer),
                        layerRect(frame.plan.eyes[static_cast<size_t>(eye)], layer));
    }
    setBorders(j.params, j.slots);
}

// Reads every cache line of the jobs' layers once, split over the arena's threads: sequential
// reads the hardware prefetchers stream at full bandwidth, where the tiles' gathers would each
// wait for memory. The layers are UCA's compulsory reads; this only moves them earlier.
void prefetchLayers(const std::vector<EyeJob>& jobs) {
    constexpr size_t kChunkBytes = size_t{64} << 10;
    struct Span {
        const uint8_t* data;
        size_t bytes;
    };
    std::vector<Span> spans;
    for (const EyeJob& j : jobs) {
        if (!j.prefetch_layers)
            continue;
        for (int k = 0; k < j.params.slot_count; ++k) {
            const detail::KernelLayer& l = j.params.slots[k];
            const size_t bytes =
                size_t{4} * static_cast<size_t>(l.width) * static_cast<size_t>(l.height);
            for (size_t off = 0; off < bytes; off += kChunkBytes)
                spans.push_back({l.texels + off, std::min(kChunkBytes, bytes - off)});
        }
    }
    tbb::parallel_for(size_t{0}, spans.size(), [&](size_t i) {
        for (size_t off = 0; off < spans[i].bytes; off += 64)
            __builtin_prefetch(spans[i].data + off, 0, 3);
    });
}

double angleRad(const glm::dvec3& a, const glm::dvec3& b) {
    // atan2 of |a×b| and a·b stays accurate for small angles.
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// An upper bound of the angle between two unit vectors a tile apart: the chord c = 2·sin(θ/2)
// underestimates θ by the factor θ/c = 1 + θ²/24 + …, below 1.02 for θ < 0.69 rad.
double smallAngleBoundRad(const glm::dvec3& unit_a, const glm::dvec3& unit_b) {
    const double chord = glm::length(unit_a - unit_b);
    return chord < 0.6 ? 1.02 * chord : angleRad(unit_a, unit_b);
}

// Which slots may carry weight somewhere in the eccentricity range [lo, hi].
uint8_t slotMaskFor(const SlotInfo& s, double lo_deg, double hi_deg) {
    uint8_t mask = 0;
    for (int k = 0; k < s.count; ++k) {
        const double starts = k == 0 ? -kInf : s.radius_deg[k - 1] - s.band_deg[k - 1];
        const double ends = s.radius_deg[k];
        if (hi_deg > starts && lo_deg < ends)
            mask = static_cast<uint8_t>(mask | (1u << k));
    }
    return mask;
}

void sampleCorner(const EyeJob& job, int point, int lattice_cols, int width, int height,
                  int chroma_count, CornerSample* out) {
    const double x = std::min((point % lattice_cols) * kTilePx, width);
    const double y = std::min((point / lattice_cols) * kTilePx, height);
    const glm::dvec3 gaze_dir(job.params.gaze[0], job.params.gaze[1], job.params.gaze[2]);
    const double scales[3] = {1.0, job.params.chroma_red, job.params.chroma_blue};
    for (int c = 0; c < chroma_count; ++c) {
        const WarpSample w = job.warp.map(x, y, scales[c]);
        const glm::dvec3 u = glm::normalize(w.dir);
        CornerSample& s = out[c];
        s.px = w.px;
        s.py = w.py;
        s.ux = u.x;
        s.uy = u.y;
        s.uz = u.z;
        s.e_deg = std::acos(std::clamp(glm::dot(u, gaze_dir), -1.0, 1.0)) * kDegPerRad;
        s.in_front = w.in_front;
    }
}

// Tile classification, once per frame, from the map at the tile's four corners (at its outer
// edges, so every pixel centre lies inside). Over 32 pixels the map is close to affine: the
// tile lands inside the corners' quadrilateral, whose points are within half its longer
// diagonal of a corner; the extra 25 % and the small constants leave slack for the map's
// curvature.
// Empty: every pixel lands off the rendered image. Single: one slot's weight is 1 over the
// whole eccentricity range. Border: anything else.
// The smallest angle from the gaze to a spherical quadrilateral given by its corners in cyclic
// order: 0 when the gaze is inside, else the nearest point of its four great-circle edges.
double nearestEccentricityDeg(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                              const glm::dvec3& d, const glm::dvec3& gaze, double corner_min_deg) {
    const glm::dvec3 corners[4] = {a, b, c, d};
    int positive = 0, negative = 0;
    double nearest = corner_min_deg;
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3& p = corners[i];
        const glm::dvec3& q = corners[(i + 1) % 4];
        glm::dvec3 n = glm::cross(p, q);
        const double n_len = glm::length(n);
        if (n_len < 1e-15)
            continue;
        n /= n_len;
        const double side = glm::dot(gaze, n);
        (side >= 0.0 ? positive : negative) += 1;
        // The gaze's foot on the edge's great circle lies between p and q when it is on the
        // inner side of both end planes.
        const glm::dvec3 foot = gaze - side * n;
        if (glm::dot(glm::cross(p, foot), n) >= 0.0 && glm::dot(glm::cross(foot, q), n) >= 0.0 &&
            glm::dot(foot, p + q) > 0.0) {
            nearest = std::min(nearest, std::asin(std::min(1.0, std::fabs(side))) * kDegPerRad);
        }
    }
    return positive == 4 || negative == 4 ? 0.0 : nearest;
}

void classifyTile(const EyeJob& job, int tile, int tile_cols, int chroma_count,
                  const CornerSample* lattice, int width, int height) {
    const glm::dvec3 gaze_dir(job.params.gaze[0], job.params.gaze[1], job.params.gaze[2]);
    const int tx = tile % tile_cols;
    const int ty = tile / tile_cols;
    const int lattice_cols = tile_cols + 1;
    const int points[4] = {ty * lattice_cols + tx, ty * lattice_cols + tx + 1,
                           (ty + 1) * lattice_cols + tx, (ty + 1) * lattice_cols + tx + 1};
    auto corners = [&](int c, const CornerSample* k[4]) {
        for (int i = 0; i < 4; ++i) {
            k[i] = &lattice[static_cast<size_t>(points[i]) * static_cast<size_t>(chroma_count) +
                            static_cast<size_t>(c)];
        }
    };
    // Emptiness first: about half the tiles of a frame are empty and need no eccentricities.
    bool empty = true;
    for (int c = 0; c < chroma_count && empty; ++c) {
        const CornerSample* k[4];
        corners(c, k);
        int front = 0;
        for (int i = 0; i < 4; ++i)
            front += k[i]->in_front ? 1 : 0;
        bool channel_empty = front == 0;
        if (front == 4) {
            // sqrt of squares: libm's hypot guards against overflow at several times the cost.
            auto dist = [](const CornerSample* a, const CornerSample* b) {
                return std::sqrt((a->px - b->px) * (a->px - b->px) +
                                 (a->py - b->py) * (a->py - b->py));
            };
            const double diag_px = std::max(dist(k[0], k[3]), dist(k[1], k[2]));
            const double margin = 0.25 * diag_px + 2.0;
            const double x_min = std::min({k[0]->px, k[1]->px, k[2]->px, k[3]->px}) - margin;
            const double x_max = std::max({k[0]->px, k[1]->px, k[2]->px, k[3]->px}) + margin;
            const double y_min = std::min({k[0]->py, k[1]->py, k[2]->py, k[3]->py}) - margin;
            const double y_max = std::max({k[0]->py, k[1]->py, k[2]->py, k[3]->py}) + margin;
            channel_empty = x_max < 0.0 || x_min > width || y_max < 0.0 || y_min > height;
        }
        empty = channel_empty;
    }
    // The lower end of the eccentricity range lies between the corners' minimum minus the
    // tile's extent and the corners' minimum (any point of a convex quadrilateral is within two
    // diagonals of a corner). When both ends give the same slot mask, the nearest-edge search
    // cannot change it and is skipped.
    double lo_deg = kInf, hi_deg = -kInf, lo_far_deg = kInf;
    double slack_of[3] = {0, 0, 0};
    double e_min_of[3] = {0, 0, 0};
    for (int c = 0; c < chroma_count && !empty; ++c) {
        const CornerSample* k[4];
        corners(c, k);
        double e_min = kInf, e_max = -kInf;
        for (int i = 0; i < 4; ++i) {
            e_min = std::min(e_min, k[i]->e_deg);
            e_max = std::max(e_max, k[i]->e_deg);
        }
        auto unit = [](const CornerSample* a) { return glm::dvec3(a->ux, a->uy, a->uz); };
        const double diag_rad = std::max(smallAngleBoundRad(unit(k[0]), unit(k[3])),
                                         smallAngleBoundRad(unit(k[1]), unit(k[2])));
        // Eccentricity is convex within the hemisphere around the gaze, so over the tile's
        // (near-geodesic) quadrilateral its maximum is at a corner and its minimum on an edge,
        // or 0 when the gaze is inside; the slack covers the edges' curvature.
        const double slack_deg = 0.125 * diag_rad * kDegPerRad + 0.01;
        slack_of[c] = slack_deg;
        e_min_of[c] = e_min;
        lo_deg = std::min(lo_deg, e_min - slack_deg);
        lo_far_deg = std::min(lo_far_deg, e_min - 2.0 * diag_rad * kDegPerRad - slack_deg);
        hi_deg = std::max(hi_deg, e_max + slack_deg);
    }
    uint8_t mask = 0;
    TileKind kind = TileKind::kEmpty;
    if (!empty) {
        mask = slotMaskFor(job.slots, lo_deg, hi_deg);
        if (slotMaskFor(job.slots, lo_far_deg, hi_deg) != mask) {
            lo_deg = kInf;
            for (int c = 0; c < chroma_count; ++c) {
                const CornerSample* k[4];
                corners(c, k);
                auto unit = [](const CornerSample* a) { return glm::dvec3(a->ux, a->uy, a->uz); };
                const double nearest_deg = nearestEccentricityDeg(
                    unit(k[0]), unit(k[1]), unit(k[3]), unit(k[2]), gaze_dir, e_min_of[c]);
                lo_deg = std::min(lo_deg, nearest_deg - slack_of[c]);
            }
            mask = slotMaskFor(job.slots, lo_deg, hi_deg);
        }
        kind = (mask & (mask - 1)) == 0 ? TileKind::kSingle : TileKind::kBorder;
    }
    (*job.kinds)[static_cast<size_t>(tile)] = kind;
    (*job.masks)[static_cast<size_t>(tile)] = mask;
}

// Classify then shade every tile of every job, in parallel over tiles of both eyes.
void runJobs(std::vector<EyeJob>& jobs, const ComposeOptions& options,
             std::array<std::vector<CornerSample>, 2>& lattices, tbb::task_arena& arena,
             TileStats& stats) {
    const bool simd = options.simd;
    const int width = jobs[0].warp.width();
    const int height = jobs[0].warp.height();
    const int cols = (width + kTilePx - 1) / kTilePx;
    const int rows = (height + kTilePx - 1) / kTilePx;
    const int per_eye = cols * rows;
    const int total = per_eye * static_cast<int>(jobs.size());
    for (auto& j : jobs) {
        j.kinds->assign(static_cast<size_t>(per_eye), TileKind::kEmpty);
        j.masks->assign(static_cast<size_t>(per_eye), 0);
    }
    // The corner lattice first (a quarter of the maps that per-tile corners would take), then
    // each tile is classified and shaded right after in the same task: a tile never waits for
    // the rest of the frame's classification (the paper's point that non-overlapping tiles need
    // not wait for composition).
    const int lattice_cols = cols + 1;
    const int lattice_per_eye = lattice_cols * (rows + 1);
    for (size_t e = 0; e < jobs.size(); ++e) {
        const int chroma_count = jobs[e].params.chroma ? 3 : 1;
        if (options.classify_tiles) {
            lattices[e].resize(static_cast<size_t>(lattice_per_eye) *
                               static_cast<size_t>(chroma_count));
        }
    }
    std::atomic<int64_t> mesh_tiles{0};
    arena.execute([&] {
        prefetchLayers(jobs);
        if (options.classify_tiles) {
            const int lattice_total = lattice_per_eye * static_cast<int>(jobs.size());
            tbb::parallel_for(tbb::blocked_range<int>(0, lattice_total, 64),
                              [&](const tbb::blocked_range<int>& r) {
                                  for (int i = r.begin(); i < r.end(); ++i) {
                                      const size_t e = static_cast<size_t>(i / lattice_per_eye);
                                      const int chroma_count = jobs[e].params.chroma ? 3 : 1;
                                      const int point = i % lattice_per_eye;
                                      sampleCorner(jobs[e], point, lattice_cols, width, height,
                                                   chroma_count,
                                                   &lattices[e][static_cast<size_t>(point) *
                                                                static_cast<size_t>(chroma_count)]);
                                  }
                              });
        }
        tbb::parallel_for(tbb::blocked_range<int>(0, total, 4),
                          [&](const tbb::blocked_range<int>& r) {
                              int64_t meshes = 0;
                              for (int i = r.begin(); i < r.end(); ++i) {
                                  const size_t e = static_cast<size_t>(i / per_eye);
                                  const EyeJob& j = jobs[e];
                                  const int tile = i % per_eye;
                                  if (options.classify_tiles) {
                                      classifyTile(j, tile, cols, j.params.chroma ? 3 : 1,
                                                   lattices[e].data(), width, height);
                                  } else {
                                      (*j.kinds)[static_cast<size_t>(tile)] = TileKind::kBorder;
                                      (*j.masks)[static_cast<size_t>(tile)] =
                                          static_cast<uint8_t>((1u << j.slots.count) - 1);
                                  }
                                  detail::TileJob t;
                                  t.x0 = (tile % cols) * kTilePx;
                                  t.y0 = (tile / cols) * kTilePx;
                                  t.x1 = std::min(t.x0 + kTilePx, width);
                                  t.y1 = std::min(t.y0 + kTilePx, height);
                                  t.slot_mask = (*j.masks)[static_cast<size_t>(tile)];
                                  t.out = j.out->data();
                                  t.out_stride_px = static_cast<size_t>(j.out->width());
                                  t.stream = j.stream_output;
                                  t.mesh = j.mesh && options.mesh_map;
                                  const bool meshed = simd ? detail::ucaTileSimd(j.params, t)
                                                           : detail::ucaTileScalar(j.params, t);
                                  meshes += meshed ? 1 : 0;
                              }
                              // Streaming stores are weakly ordered: make this range's visible
                              // before it counts as done. Once per range, not per tile: each
                              // fence waits for the write-combining buffers to drain, which
                              // per tile cost more than a millisecond a frame.
                              detail::ucaFenceStreams();
                              mesh_tiles.fetch_add(meshes, std::memory_order_relaxed);
                          });
    });
    stats.mesh += mesh_tiles.load(std::memory_order_relaxed);
    for (const auto& j : jobs) {
        for (TileKind k : *j.kinds) {
            if (k == TileKind::kEmpty)
                ++stats.empty;
            if (k == TileKind::kSingle)
                ++stats.single;
            if (k == TileKind::kBorder)
                ++stats.border;
        }
    }
}

void ensureSize(ImageRgba8& image, int width, int height) {
    if (image.width() != width || image.height() != height)
        image.resize(width, height);
}

HmdProfile withoutLens(const HmdProfile& profile) {
    HmdProfile p = profile;
    p.lens = LensProfile{0.0, 0.0, 1.0, 1.0};
    return p;
}

}  // namespace

Status validateFrame(const HmdProfile& profile, const LayerFrame& frame) {
    const LayerPlan& plan = frame.plan;
    const int width = profile.width_px;
    const int height = profile.height_px;
    if (width <= 0 || height <= 0)
        return makeError("compose: the HMD profile has no pixels");
    if (plan.full_pixels != static_cast<int64_t>(width) * height) {
        return makeError(fmt::format(
            "compose: the layer plan is for {} pixels per eye but the display has {}x{}",
            plan.full_pixels, width, height));
    }
    if (!std::isfinite(plan.e1_deg) || !std::isfinite(plan.e2_deg) || plan.e1_deg < 0.0 ||
        plan.e2_deg < plan.e1_deg) {
        return makeError(
            fmt::format("compose: the plan's radii e1 = {} and e2 = {} are not "
                        "0 <= e1 <= e2",
                        plan.e1_deg, plan.e2_deg));
    }
    if (!std::isfinite(plan.gaze.x_deg) || !std::isfinite(plan.gaze.y_deg) ||
        std::fabs(plan.gaze.x_deg) >= 89.0 || std::fabs(plan.gaze.y_deg) >= 89.0) {
        return makeError("compose: the plan's gaze is not a finite angle within ±89°");
    }
    if (int64_t{width} * height >= kMaxTexels) {
        return makeError(fmt::format("compose: a {}x{} eye has more than the kernel's 2^24 pixels",
                                     width, height));
    }
    const PixelRect full{0, 0, width, height};
    for (int eye = 0; eye < 2; ++eye) {
        const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
        const EyeLayerImages& images = frame.eyes[static_cast<size_t>(eye)];
        int last = -1;
        for (int k = 0; k < 3; ++k) {
            const LayerRect& r = layerRect(layers, k);
            const ImageRgba8& img = layerImage(images, k);
            const char* eye_name = eye == 0 ? "left" : "right";
            if (r.empty()) {
                if (!img.empty()) {
                    return makeError(
                        fmt::format("compose: {} {} layer has an image but the plan "
                                    "leaves that layer out",
                                    eye_name, kLayerNames[k]));
                }
                continue;
            }
            if (!std::isfinite(r.scale) || r.scale < 1.0 || r.scale > 1024.0) {
                return makeError(fmt::format("compose: {} {} layer scale {} is outside [1, 1024]",
                                             eye_name, kLayerNames[k], r.scale));
            }
            if (r.rect.empty() || !full.contains(r.rect)) {
                return makeError(fmt::format(
                    "compose: {} {} layer rect [{},{})x[{},{}) is empty or outside the {}x{} "
                    "eye image",
                    eye_name, kLayerNames[k], r.rect.x0, r.rect.x1, r.rect.y0, r.rect.y1, width,
                    height));
            }
            if (img.width() != r.width_px || img.height() != r.height_px) {
                return makeError(fmt::format(
                    "compose: {} {} layer image is {}x{} but the plan says {}x{}", eye_name,
                    kLayerNames[k], img.width(), img.height(), r.width_px, r.height_px));
            }
            if (r.width_px * r.scale < r.rect.width() - 1e-6 ||
                r.height_px * r.scale < r.rect.height() - 1e-6) {
                return makeError(fmt::format(
                    "compose: {} {} layer of {}x{} texels at scale {} does not cover its rect",
                    eye_name, kLayerNames[k], r.width_px, r.height_px, r.scale));
            }
            if (r.pixels() >= kMaxTexels) {
                return makeError(
                    fmt::format("compose: {} {} layer has {} texels, more than the "
                                "kernel's 2^24",
                                eye_name, kLayerNames[k], r.pixels()));
            }
            last = k;
        }
        if (last < 0)
            return makeError("compose: the plan has no layer for an eye");
        if (!(layerRect(layers, last).rect == full)) {
            return makeError(
                fmt::format("compose: the outermost {} layer does not cover the whole eye image",
                            kLayerNames[last]));
        }
    }
    return Status::success();
}

Compositor::Compositor(const HmdProfile& profile, ComposeOptions options)
    : m_profile(profile), m_options(options) {
    m_arena = options.threads > 0 ? std::make_unique<tbb::task_arena>(options.threads)
                                  : std::make_unique<tbb::task_arena>();
}

Compositor::~Compositor() = default;

int Compositor::tileColumns() const {
    return (m_profile.width_px + kTilePx - 1) / kTilePx;
}
int Compositor::tileRows() const {
    return (m_profile.height_px + kTilePx - 1) / kTilePx;
}

Expected<ComposeReport> Compositor::compose(const LayerFrame& frame, const Pose& display_pose,
                                            std::array<ImageRgba8, 2>& out) {
    if (Status st = validateFrame(m_profile, frame); !st)
        return makeError(st.error());
    std::vector<EyeJob> jobs;
    jobs.reserve(2);
    for (int eye = 0; eye < 2; ++eye) {
        EyeJob j{EyeWarp(m_profile, frame.render_pose.orientation, display_pose.orientation),
                 slotsOf(m_profile, frame.plan, eye, m_options.blend_band_texels),
                 {},
                 &out[static_cast<size_t>(eye)],
                 &m_tile_kinds[static_cast<size_t>(eye)],
                 &m_tile_masks[static_cast<size_t>(eye)]};
        setWarpParams(j.params, j.warp, frame.plan.gaze, m_options.chromatic_aberration);
        bindLayers(j, frame, eye);
        ensureSize(out[static_cast<size_t>(eye)], m_profile.width_px, m_profile.height_px);
        j.mesh = true;
        j.prefetch_layers = true;
        jobs.push_back(std::move(j));
    }
    ComposeReport report;
    report.frame_index = frame.frame_index;
    report.warp_deg = angleBetweenDeg(frame.render_pose.orientation, display_pose.orientation);
    runJobs(jobs, m_options, m_lattices, *m_arena, report.tiles);
    return report;
}

Expected<ComposeReport> Compositor::present(std::shared_ptr<const LayerFrame> arrived,
                                            const Pose& display_pose,
                                            std::array<ImageRgba8, 2>& out) {
    if (arrived) {
        if (Status st = validateFrame(m_profile, *arrived); !st)
            return makeError(st.error());
        m_newest = std::move(arrived);
        m_reused_in_a_row = 0;
        return compose(*m_newest, display_pose, out);
    }
    if (!m_newest) {
        return makeError("compose: the layers are late and no earlier frame exists to reuse");
    }
    auto report = compose(*m_newest, display_pose, out);
    if (!report)
        return report;
    report->reused = true;
    report->reused_in_a_row = ++m_reused_in_a_row;
    return report;
}

Expected<ComposeReport> Compositor::composeTwoPass(const LayerFrame& frame,
                                                   const Pose& display_pose,
                                                   std::array<ImageRgba8, 2>& out,
                                                   std::array<ImageRgba8, 2>* eye_buffers) {
    if (Status st = validateFrame(m_profile, frame); !st)
        return makeError(st.error());
    std::array<ImageRgba8, 2>& buffers = eye_buffers ? *eye_buffers : m_two_pass_buffers;
    ComposeReport report;
    report.frame_index = frame.frame_index;
    report.warp_deg = angleBetweenDeg(frame.render_pose.orientation, display_pose.orientation);
    // Pass 1: composition at full resolution in the render pose — the identity map, the same
    // layer filter and blend band.
    const HmdProfile flat = withoutLens(m_profile);
    std::vector<EyeJob> compose_jobs;
    for (int eye = 0; eye < 2; ++eye) {
        EyeJob j{EyeWarp(flat, frame.render_pose.orientation, frame.render_pose.orientation),
                 slotsOf(m_profile, frame.plan, eye, m_options.blend_band_texels),
                 {},
                 &buffers[static_cast<size_t>(eye)],
                 &m_tile_kinds[static_cast<size_t>(eye)],
                 &m_tile_masks[static_cast<size_t>(eye)]};
        setWarpParams(j.params, j.warp, frame.plan.gaze, false);
        j.params.identity_map = true;
        bindLayers(j, frame, eye);
        ensureSize(buffers[static_cast<size_t>(eye)], m_profile.width_px, m_profile.height_px);
        j.stream_output = false;
        compose_jobs.push_back(std::move(j));
    }
    TileStats pass1;
    runJobs(compose_jobs, m_options, m_lattices, *m_arena, pass1);
    // Pass 2: timewarp + lens of the composed buffer, one full-resolution layer.
    LayerRect full_rect;
    full_rect.rect = {0, 0, m_profile.width_px, m_profile.height_px};
    full_rect.scale = 1.0;
    std::vector<EyeJob> warp_jobs;
    for (int eye = 0; eye < 2; ++eye) {
        EyeJob j{EyeWarp(m_profile, frame.render_pose.orientation, display_pose.orientation),
                 SlotInfo{},
                 {},
                 &out[static_cast<size_t>(eye)],
                 &m_tile_kinds[static_cast<size_t>(eye)],
                 &m_tile_masks[static_cast<size_t>(eye)]};
        j.slots.count = 1;
        setWarpParams(j.params, j.warp, frame.plan.gaze, m_options.chromatic_aberration);
        j.params.slot_count = 1;
        j.params.slots[0] = kernelLayer(buffers[static_cast<size_t>(eye)], full_rect);
        setBorders(j.params, j.slots);
        ensureSize(out[static_cast<size_t>(eye)], m_profile.width_px, m_profile.height_px);
        warp_jobs.push_back(std::move(j));
    }
    runJobs(warp_jobs, m_options, m_lattices, *m_arena, report.tiles);
    return report;
}

}  // namespace qvr

namespace qvr::detail {

KernelParams composeParams(const HmdProfile& profile, const LayerFrame& frame, int eye,
                           double blend_band_texels) {
    const EyeWarp warp(withoutLens(profile), frame.render_pose.orientation,
                       frame.render_pose.orientation);
    const SlotInfo slots = slotsOf(profile, frame.plan, eye, blend_band_texels);
    KernelParams p;
    setWarpParams(p, warp, frame.plan.gaze, false);
    p.identity_map = true;
    p.slot_count = slots.count;
    for (int k = 0; k < slots.count; ++k) {
        p.slots[k] =
            kernelLayer(layerImage(frame.eyes[static_cast<size_t>(eye)], slots.layer[k]),
                        layerRect(frame.plan.eyes[static_cast<size_t>(eye)], slots.layer[k]));
    }
    setBorders(p, slots);
    return p;
}

KernelParams timewarpParams(const HmdProfile& profile, const Pose& render_pose,
                            const Pose& display_pose, const Gaze& gaze) {
    const EyeWarp warp(profile, render_pose.orientation, display_pose.orientation);
    KernelParams p;
    setWarpParams(p, warp, gaze, false);
    return p;
}

SlotInfo slotBands(const HmdProfile& profile, const LayerPlan& plan, int eye,
                   double blend_band_texels) {
    return slotsOf(profile, plan, eye, blend_band_texels);
}

void slotLayers(const LayerPlan& plan, int eye, int layer_of_slot[3], int& slot_count) {
    slot_count = 0;
    for (int k = 0; k < 3; ++k) {
        if (!layerRect(plan.eyes[static_cast<size_t>(eye)], k).empty()) {
            layer_of_slot[slot_count++] = k;
        }
    }
}

}  // namespace qvr::detail
