// One geometry pass for the middle and outer layers of an eye (periphery_pass.h).
#include "qvr/render/periphery_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace qvr {

PeripheryGrid peripheryGrid(const EyeLayers& layers) {
    const LayerRect& m = layers.middle;
    const LayerRect& o = layers.outer;
    PeripheryGrid g;
    if (m.empty() || o.empty() || !(o.scale > m.scale) || !(m.scale >= 1.0))
        return g;
    g.scale = m.scale;
    // Step the middle layer's grid outwards by whole texels until it starts at or before the
    // outer layer's first pixel and ends at or after the outer grid's last one.
    const double eps = 1e-9;
    g.middle_col =
        std::max(0, static_cast<int>(std::ceil((m.rect.x0 - o.rect.x0) / m.scale - eps)));
    g.middle_row =
        std::max(0, static_cast<int>(std::ceil((m.rect.y0 - o.rect.y0) / m.scale - eps)));
    g.x0 = m.rect.x0 - g.middle_col * m.scale;
    g.y0 = m.rect.y0 - g.middle_row * m.scale;
    const double x_end =
        std::max(o.rect.x0 + o.width_px * o.scale, m.rect.x0 + m.width_px * m.scale);
    const double y_end =
        std::max(o.rect.y0 + o.height_px * o.scale, m.rect.y0 + m.height_px * m.scale);
    g.width_px = static_cast<int>(std::ceil((x_end - g.x0) / m.scale - eps));
    g.height_px = static_cast<int>(std::ceil((y_end - g.y0) / m.scale - eps));
    return g;
}

bool onePassPays(const EyeLayers& layers, double max_fill_ratio) {
    const PeripheryGrid g = peripheryGrid(layers);
    if (g.pixels() == 0)
        return false;
    const double separate = double(layers.middle.pixels()) + double(layers.outer.pixels());
    return double(g.pixels()) <= max_fill_ratio * separate;
}

namespace {

// One output texel's taps along an axis: the grid texels [first, first + weights.size()).
struct Taps {
    int first = 0;
    std::vector<float> weights;
};

// Footprints [origin + i·step, origin + (i+1)·step) in grid texel units, i < count, against grid
// texels [k, k+1), k < size (taps past the edge fold onto the edge texel).
std::vector<Taps> boxTaps(double origin, double step, int count, int size) {
    std::vector<Taps> taps(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) {
        const double a = origin + i * step;
        const double b = a + step;
        const int k0 = static_cast<int>(std::floor(a));
        const int k1 = static_cast<int>(std::ceil(b));
        Taps& t = taps[static_cast<size_t>(i)];
        const int lo = std::clamp(k0, 0, size - 1);
        const int hi = std::clamp(k1 - 1, 0, size - 1);
        t.first = lo;
        t.weights.assign(static_cast<size_t>(hi - lo + 1), 0.0f);
        for (int k = k0; k < k1; ++k) {
            const double overlap = std::min(b, double(k + 1)) - std::max(a, double(k));
            if (overlap <= 0.0)
                continue;
            const int kc = std::clamp(k, lo, hi);
            t.weights[static_cast<size_t>(kc - lo)] += static_cast<float>(overlap / step);
        }
    }
    return taps;
}

}  // namespace

void reduceToOuter(const ImageRgba8& grid_image, const PeripheryGrid& grid, const LayerRect& outer,
                   ImageRgba8& out) {
    out.resize(outer.width_px, outer.height_px);
    if (outer.empty() || grid_image.empty())
        return;
    const double step = outer.scale / grid.scale;
    const auto cols =
        boxTaps((outer.rect.x0 - grid.x0) / grid.scale, step, outer.width_px, grid_image.width());
    const auto rows =
        boxTaps((outer.rect.y0 - grid.y0) / grid.scale, step, outer.height_px, grid_image.height());
    // Horizontal pass into floats (the rows an output row needs), then vertical.
    const int gw = grid_image.width();
    const int gh = grid_image.height();
    std::vector<float> horiz(static_cast<size_t>(gh) * outer.width_px * 3);
    for (int y = 0; y < gh; ++y) {
        const uint8_t* src = grid_image.data() + static_cast<size_t>(y) * gw * 4;
        float* dst = horiz.data() + static_cast<size_t>(y) * outer.width_px * 3;
        for (int i = 0; i < outer.width_px; ++i) {
            const Taps& t = cols[static_cast<size_t>(i)];
            float r = 0, g = 0, b = 0;
            for (size_t k = 0; k < t.weights.size(); ++k) {
                const uint8_t* p = src + (static_cast<size_t>(t.first) + k) * 4;
                const float w = t.weights[k];
                r += w * p[0];
                g += w * p[1];
                b += w * p[2];
            }
            dst[3 * i + 0] = r;
            dst[3 * i + 1] = g;
            dst[3 * i + 2] = b;
        }
    }
    for (int j = 0; j < outer.height_px; ++j) {
        const Taps& t = rows[static_cast<size_t>(j)];
        uint8_t* dst = out.data() + static_cast<size_t>(j) * outer.width_px * 4;
        for (int i = 0; i < outer.width_px; ++i) {
            float c[3] = {0, 0, 0};
            for (size_t k = 0; k < t.weights.size(); ++k) {
                const float* p =
                    horiz.data() + ((static_cast<size_t>(t.first) + k) * outer.width_px + i) * 3;
                const float w = t.weights[k];
                c[0] += w * p[0];
                c[1] += w * p[1];
                c[2] += w * p[2];
            }
            for (int ch = 0; ch < 3; ++ch)
                dst[4 * i + ch] = static_cast<uint8_t>(std::clamp(c[ch] + 0.5f, 0.0f, 255.0f));
            dst[4 * i + 3] = 255;
        }
    }
}

void cropMiddle(const ImageRgba8& grid_image, const PeripheryGrid& grid, const LayerRect& middle,
                ImageRgba8& out) {
    out.resize(middle.width_px, middle.height_px);
    const int w = std::min(middle.width_px, grid_image.width() - grid.middle_col);
    const int h = std::min(middle.height_px, grid_image.height() - grid.middle_row);
    if (w <= 0 || h <= 0)
        return;
    for (int y = 0; y < h; ++y) {
        const uint8_t* src =
            grid_image.data() +
            (static_cast<size_t>(y + grid.middle_row) * grid_image.width() + grid.middle_col) * 4;
        std::memcpy(out.data() + static_cast<size_t>(y) * middle.width_px * 4, src,
                    static_cast<size_t>(w) * 4);
    }
}

Expected<RenderStats> renderPeriphery(Renderer& renderer, const HmdProfile& profile,
                                      const LayerPlan& plan, const Pose& head, Eye eye,
                                      ImageRgba8& middle, ImageRgba8& outer, ImageRgba8& scratch,
                                      const CameraOptions& options) {
    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
    const PeripheryGrid grid = peripheryGrid(layers);
    if (grid.pixels() == 0)
        return makeError("one-pass periphery: the eye needs a middle and a coarser outer layer");
    RenderView v;
    v.width_px = grid.width_px;
    v.height_px = grid.height_px;
    v.view = viewMatrix(eyePose(head, eye, options.ipd_m));
    v.projection = regionProjection(profile, grid.x0, grid.y0, grid.x0 + grid.width_px * grid.scale,
                                    grid.y0 + grid.height_px * grid.scale, options);
    auto stats = renderer.render(v, scratch);
    if (!stats)
        return stats;
    cropMiddle(scratch, grid, layers.middle, middle);
    reduceToOuter(scratch, grid, layers.outer, outer);
    return stats;
}

}  // namespace qvr
