// The analytic test pattern, its layers and the double-precision ground-truth warp (the
// quality measure for UCA, paper §4.2).
#include "qvr/compose/test_pattern.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "qvr/compose/warp.h"
#include "uca_kernel.h"

namespace qvr {

namespace {

constexpr double kPi = 3.14159265358979323846;

uint32_t hash2(int64_t x, int64_t y) {
    uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
                 (static_cast<uint64_t>(y) + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    return static_cast<uint32_t>(h);
}

uint8_t toByte(double v) {
    return static_cast<uint8_t>(std::clamp(static_cast<int>(std::lround(v)), 0, 255));
}

}  // namespace

void testPatternAt(double px, double py, int width, int height, double rgb[3]) {
    const double u = px / width;
    const double v = py / height;
    // Gradients: a colour ramp across the image and a checkerboard of 64-pixel squares whose
    // edges are sharp at any scale.
    const int64_t cell_x = static_cast<int64_t>(std::floor(px / 64.0));
    const int64_t cell_y = static_cast<int64_t>(std::floor(py / 64.0));
    const bool dark = ((cell_x + cell_y) & 1) != 0;
    if (dark) {
        rgb[0] = 40.0 + 120.0 * u;
        rgb[1] = 50.0 + 100.0 * v;
        rgb[2] = 150.0 - 80.0 * u;
    } else {
        rgb[0] = 230.0 - 60.0 * v;
        rgb[1] = 200.0 + 40.0 * u;
        rgb[2] = 120.0 + 110.0 * v;
    }
    // Text-like detail: in three of four light squares, lines of 6×10-pixel "glyphs" made of
    // 2-pixel strokes on a 3×5 grid chosen by a hash.
    const double lx = px - 64.0 * static_cast<double>(cell_x);
    const double ly = py - 64.0 * static_cast<double>(cell_y);
    if (!dark && (hash2(cell_x, cell_y) & 3u) != 0 && lx >= 4.0 && lx < 60.0 && ly >= 4.0 &&
        ly < 60.0) {
        const int gx = static_cast<int>((lx - 4.0) / 8.0);   // glyph column, 8 px pitch
        const int gy = static_cast<int>((ly - 4.0) / 12.0);  // text line, 12 px pitch
        const double ox = lx - 4.0 - 8.0 * gx;
        const double oy = ly - 4.0 - 12.0 * gy;
        if (ox < 6.0 && oy < 10.0) {
            const int sx = static_cast<int>(ox / 2.0);
            const int sy = static_cast<int>(oy / 2.0);
            const uint32_t bits = hash2(cell_x * 64 + gx, cell_y * 64 + gy);
            if ((bits >> (sy * 3 + sx)) & 1u) {
                rgb[0] = 15.0;
                rgb[1] = 20.0;
                rgb[2] = 35.0;
            }
        }
    }
    // A Siemens star at the image centre: radial edges at every angle and ever finer detail
    // towards its middle.
    const double dx = px - 0.5 * width;
    const double dy = py - 0.5 * height;
    const double r = std::hypot(dx, dy);
    const double star_radius = 0.09 * std::min(width, height);
    if (r < star_radius) {
        const double a = std::atan2(dy, dx);
        const bool white = (static_cast<int64_t>(std::floor(a * 18.0 / kPi)) & 1) != 0;
        const double level = white ? 245.0 : 10.0;
        rgb[0] = rgb[1] = rgb[2] = level;
    }
    // Thin rings: one-pixel-wide circles every 96 pixels from the centre.
    const double ring = std::fmod(r, 96.0);
    if (r >= star_radius && ring >= 47.5 && ring < 48.5) {
        rgb[0] = 255.0;
        rgb[1] = 40.0;
        rgb[2] = 40.0;
    }
}

ImageRgba8 renderTestPattern(int width, int height) {
    ImageRgba8 image(width, height);
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) {
            uint8_t* row = image.row(y);
            for (int x = 0; x < width; ++x) {
                double rgb[3];
                testPatternAt(x + 0.5, y + 0.5, width, height, rgb);
                row[4 * x + 0] = toByte(rgb[0]);
                row[4 * x + 1] = toByte(rgb[1]);
                row[4 * x + 2] = toByte(rgb[2]);
                row[4 * x + 3] = 255;
            }
        }
    });
    return image;
}

namespace {

ImageRgba8 renderLayer(const LayerRect& layer, int width, int height) {
    if (layer.empty())
        return {};
    ImageRgba8 image(layer.width_px, layer.height_px);
    constexpr int kSuper = 4;
    tbb::parallel_for(
        tbb::blocked_range<int>(0, layer.height_px, 4), [&](const tbb::blocked_range<int>& r) {
            for (int j = r.begin(); j < r.end(); ++j) {
                uint8_t* row = image.row(j);
                for (int i = 0; i < layer.width_px; ++i) {
                    double sum[3] = {0, 0, 0};
                    for (int a = 0; a < kSuper; ++a) {
                        for (int b = 0; b < kSuper; ++b) {
                            const double px =
                                layer.rect.x0 + (i + (b + 0.5) / kSuper) * layer.scale;
                            const double py =
                                layer.rect.y0 + (j + (a + 0.5) / kSuper) * layer.scale;
                            double rgb[3];
                            testPatternAt(px, py, width, height, rgb);
                            for (int c = 0; c < 3; ++c)
                                sum[c] += rgb[c];
                        }
                    }
                    for (int c = 0; c < 3; ++c)
                        row[4 * i + c] = toByte(sum[c] / (kSuper * kSuper));
                    row[4 * i + 3] = 255;
                }
            }
        });
    return image;
}

ImageRgba8 cropFovea(const LayerRect& layer, const ImageRgba8& full) {
    if (layer.empty())
        return {};
    ImageRgba8 image(layer.width_px, layer.height_px);
    for (int j = 0; j < layer.height_px; ++j) {
        const int sy = std::min(layer.rect.y0 + j, full.height() - 1);
        for (int i = 0; i < layer.width_px; ++i) {
            const int sx = std::min(layer.rect.x0 + i, full.width() - 1);
            for (int c = 0; c < 4; ++c)
                image.at(i, j, c) = full.at(sx, sy, c);
        }
    }
    return image;
}

}  // namespace

LayerFrame makeTestPatternFrame(const HmdProfile& profile, const LayerPlan& plan,
                                const Pose& render_pose, uint64_t frame_index,
                                const ImageRgba8& full_render) {
    LayerFrame frame;
    frame.frame_index = frame_index;
    frame.plan = plan;
    frame.render_pose = render_pose;
    for (size_t eye = 0; eye < 2; ++eye) {
        const EyeLayers& l = plan.eyes[eye];
        // A scale-1 layer is a plain crop of the full render (the fovea, or any layer of an
        // all-fovea plan); coarser layers are rendered at their own resolution.
        auto layerOf = [&](const LayerRect& r) {
            return r.scale == 1.0 ? cropFovea(r, full_render)
                                  : renderLayer(r, profile.width_px, profile.height_px);
        };
        frame.eyes[eye].fovea = layerOf(l.fovea);
        frame.eyes[eye].middle = layerOf(l.middle);
        frame.eyes[eye].outer = layerOf(l.outer);
    }
    return frame;
}

ImageRgbD groundTruthWarp(const HmdProfile& profile, const ImageRgba8& full_render,
                          const Pose& render_pose, const Pose& display_pose,
                          bool chromatic_aberration) {
    const EyeWarp warp(profile, render_pose.orientation, display_pose.orientation);
    const int width = profile.width_px;
    const int height = profile.height_px;
    ImageRgbD truth(width, height);
    const double scales[3] = {chromatic_aberration ? profile.lens.chroma_red_scale : 1.0, 1.0,
                              chromatic_aberration ? profile.lens.chroma_blue_scale : 1.0};
    auto sample = [&](double px, double py, int c) {
        const double lx = px - 0.5;
        const double ly = py - 0.5;
        const double fx = std::floor(lx);
        const double fy = std::floor(ly);
        const double wx = lx - fx;
        const double wy = ly - fy;
        const int ix = static_cast<int>(fx);
        const int iy = static_cast<int>(fy);
        const int x0 = std::clamp(ix, 0, width - 1);
        const int x1 = std::clamp(ix + 1, 0, width - 1);
        const int y0 = std::clamp(iy, 0, height - 1);
        const int y1 = std::clamp(iy + 1, 0, height - 1);
        const double top = (1 - wx) * full_render.at(x0, y0, c) + wx * full_render.at(x1, y0, c);
        const double bot = (1 - wx) * full_render.at(x0, y1, c) + wx * full_render.at(x1, y1, c);
        return (1 - wy) * top + wy * bot;
    };
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) {
            for (int x = 0; x < width; ++x) {
                for (int c = 0; c < 3; ++c) {
                    const WarpSample s = warp.map(x + 0.5, y + 0.5, scales[c]);
                    truth.at(x, y, c) = s.inside ? sample(s.px, s.py, c) : 0.0;
                }
            }
        }
    });
    return truth;
}

namespace {

// Bilinear, clamp-to-edge, in double: channel c of a layer at a rendered-image point.
double sampleLayerD(const ImageRgba8& img, const LayerRect& r, double px, double py, int c) {
    const double lx = std::clamp((px - r.rect.x0) / r.scale - 0.5, 0.0, img.width() - 1.0);
    const double ly = std::clamp((py - r.rect.y0) / r.scale - 0.5, 0.0, img.height() - 1.0);
    const int x0 = static_cast<int>(lx);
    const int y0 = static_cast<int>(ly);
    const int x1 = std::min(x0 + 1, img.width() - 1);
    const int y1 = std::min(y0 + 1, img.height() - 1);
    const double wx = lx - x0;
    const double wy = ly - y0;
    const double top = (1 - wx) * img.at(x0, y0, c) + wx * img.at(x1, y0, c);
    const double bot = (1 - wx) * img.at(x0, y1, c) + wx * img.at(x1, y1, c);
    return (1 - wy) * top + wy * bot;
}

}  // namespace

ImageRgbD layerReferenceWarp(const HmdProfile& profile, const LayerFrame& frame, int eye,
                             const Pose& display_pose, double blend_band_texels,
                             bool chromatic_aberration) {
    const EyeWarp warp(profile, frame.render_pose.orientation, display_pose.orientation);
    const detail::SlotInfo slots = detail::slotBands(profile, frame.plan, eye, blend_band_texels);
    const EyeLayers& rects = frame.plan.eyes[static_cast<size_t>(eye)];
    const EyeLayerImages& images = frame.eyes[static_cast<size_t>(eye)];
    const LayerRect* slot_rect[3];
    const ImageRgba8* slot_image[3];
    for (int k = 0; k < slots.count; ++k) {
        const int l = slots.layer[k];
        slot_rect[k] = l == 0 ? &rects.fovea : (l == 1 ? &rects.middle : &rects.outer);
        slot_image[k] = l == 0 ? &images.fovea : (l == 1 ? &images.middle : &images.outer);
    }
    const double gx = std::tan(frame.plan.gaze.x_deg * kPi / 180.0);
    const double gy = std::tan(frame.plan.gaze.y_deg * kPi / 180.0);
    const double g_norm = std::sqrt(gx * gx + gy * gy + 1.0);
    const double scales[3] = {chromatic_aberration ? profile.lens.chroma_red_scale : 1.0, 1.0,
                              chromatic_aberration ? profile.lens.chroma_blue_scale : 1.0};
    ImageRgbD out(profile.width_px, profile.height_px);
    tbb::parallel_for(
        tbb::blocked_range<int>(0, profile.height_px, 8), [&](const tbb::blocked_range<int>& rows) {
            for (int y = rows.begin(); y < rows.end(); ++y) {
                for (int x = 0; x < profile.width_px; ++x) {
                    for (int c = 0; c < 3; ++c) {
                        const WarpSample s = warp.map(x + 0.5, y + 0.5, scales[c]);
                        if (!s.inside) {
                            out.at(x, y, c) = 0.0;
                            continue;
                        }
                        const double len =
                            std::sqrt(s.dir.x * s.dir.x + s.dir.y * s.dir.y + s.dir.z * s.dir.z);
                        const double cos_e =
                            (gx * s.dir.x + gy * s.dir.y - s.dir.z) / (len * g_norm);
                        double t[2] = {0.0, 0.0};
                        for (int k = 0; k + 1 < slots.count && k < 2; ++k) {
                            const double hi =
                                std::cos((slots.radius_deg[k] - slots.band_deg[k]) * kPi / 180.0);
                            const double lo = std::cos(slots.radius_deg[k] * kPi / 180.0);
                            t[k] = std::clamp((hi - cos_e) / (hi - lo), 0.0, 1.0);
                        }
                        const double w[3] = {1.0 - t[0], t[0] * (1.0 - t[1]), t[0] * t[1]};
                        double v = 0.0;
                        for (int k = 0; k < slots.count; ++k) {
                            if (w[k] > 0.0)
                                v += w[k] *
                                     sampleLayerD(*slot_image[k], *slot_rect[k], s.px, s.py, c);
                        }
                        out.at(x, y, c) = v;
                    }
                }
            }
        });
    return out;
}

}  // namespace qvr
