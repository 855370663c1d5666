#include "qvr/sim/cost_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

namespace qvr {

namespace {

// Solves the k×k normal equations a·x = b (a is k rows of k + 1, the last column b) by
// Gauss-Jordan elimination with partial pivoting; a singular column gets 0.
std::vector<double> solve(std::vector<std::vector<double>> a) {
    const size_t k = a.size();
    for (size_t c = 0; c < k; ++c) {
        size_t p = c;
        for (size_t r = c + 1; r < k; ++r)
            if (std::fabs(a[r][c]) > std::fabs(a[p][c]))
                p = r;
        std::swap(a[c], a[p]);
        if (std::fabs(a[c][c]) < 1e-12)
            continue;
        for (size_t r = 0; r < k; ++r) {
            if (r == c)
                continue;
            const double m = a[r][c] / a[c][c];
            for (size_t j = c; j <= k; ++j)
                a[r][j] -= m * a[c][j];
        }
    }
    std::vector<double> x(k, 0.0);
    for (size_t c = 0; c < k; ++c)
        x[c] = std::fabs(a[c][c]) < 1e-12 ? 0.0 : a[c][k] / a[c][c];
    return x;
}

// Weighted least squares of y on the features; w, y and the features per sample.
std::vector<double> leastSquares(const std::vector<CostSample>& s,
                                 const std::vector<std::function<double(const CostSample&)>>& f,
                                 const std::function<double(const CostSample&)>& y,
                                 const std::function<double(const CostSample&)>& w) {
    const size_t k = f.size();
    std::vector<std::vector<double>> a(k, std::vector<double>(k + 1, 0.0));
    for (const CostSample& x : s) {
        const double wx = w(x);
        for (size_t i = 0; i < k; ++i) {
            for (size_t j = 0; j < k; ++j)
                a[i][j] += wx * f[i](x) * f[j](x);
            a[i][k] += wx * f[i](x) * y(x);
        }
    }
    return solve(std::move(a));
}

PartCost fitLinear(const std::vector<CostSample>& s, bool use_px, bool use_tri,
                   bool use_frag = false) {
    bool use_base = true;
    for (;;) {
        std::vector<std::function<double(const CostSample&)>> f;
        if (use_base)
            f.push_back([](const CostSample&) { return 1.0; });
        if (use_px)
            f.push_back([](const CostSample& x) { return x.pixels * 1e-6; });
        if (use_frag)
            f.push_back([](const CostSample& x) { return x.fragments * 1e-6; });
        if (use_tri)
            f.push_back([](const CostSample& x) { return x.triangles * 1e-3; });
        PartCost cost;
        if (f.empty())
            return cost;
        const std::vector<double> beta = leastSquares(
            s, f, [](const CostSample& x) { return x.ms; },
            [](const CostSample& x) { return 1.0 / std::max(x.ms * x.ms, 0.01); });
        size_t idx = 0;
        if (use_base)
            cost.base_ms = beta[idx++];
        if (use_px)
            cost.ms_per_mpx = beta[idx++];
        if (use_frag)
            cost.ms_per_mfrag = beta[idx++];
        if (use_tri)
            cost.ms_per_ktri = beta[idx++];
        if (use_frag && cost.ms_per_mfrag <= 0) {
            use_frag = false;  // fragments that cost nothing: the pixels' law instead
            use_px = true;
            continue;
        }
        if (use_tri && cost.ms_per_ktri < 0) {
            use_tri = false;
            continue;
        }
        if (use_px && cost.ms_per_mpx < 0) {
            use_px = false;
            continue;
        }
        if (use_base && cost.base_ms < 0) {
            // Through the origin, refitted: clamping the intercept alone would leave slopes
            // fitted beside a negative one and overcharge every small pass.
            use_base = false;
            continue;
        }
        return cost;
    }
}

PartCost fitPower(const std::vector<CostSample>& s, bool use_px, bool use_tri) {
    std::vector<CostSample> pos;
    for (const CostSample& x : s)
        if (x.ms > 0.0 && x.pixels > 0.0)
            pos.push_back(x);
    PartCost cost;
    if (pos.size() < 3)
        return cost;
    // The same floors PartCost::at applies.
    auto lpx = [](const CostSample& x) { return std::log(std::max(x.pixels * 1e-6, 1e-6)); };
    auto ltri = [](const CostSample& x) { return std::log(std::max(x.triangles * 1e-3, 0.01)); };
    std::vector<std::function<double(const CostSample&)>> f = {
        [](const CostSample&) { return 1.0; }};
    if (use_px)
        f.push_back(lpx);
    if (use_tri)
        f.push_back(ltri);
    const std::vector<double> beta = leastSquares(
        pos, f, [](const CostSample& x) { return std::log(x.ms); },
        [](const CostSample&) { return 1.0; });
    size_t idx = 0;
    cost.power_coef_ms = std::exp(beta[idx++]);
    if (use_px)
        cost.px_exponent = std::clamp(beta[idx++], -4.0, 4.0);
    if (use_tri)
        cost.tri_exponent = std::clamp(beta[idx++], -4.0, 4.0);
    return cost;
}

}  // namespace

double costResidualRmsPct(const std::vector<CostSample>& samples, const PartCost& cost) {
    double sq = 0.0;
    size_t n = 0;
    for (const CostSample& x : samples) {
        if (x.ms <= 0.0)
            continue;
        const double p = x.full_frame ? cost.atFullFrame(x.pixels, x.triangles, x.fragments)
                                      : cost.at(x.pixels, x.triangles, x.fragments);
        const double r = (x.ms - p) / x.ms;
        sq += r * r;
        ++n;
    }
    return n == 0 ? 0.0 : 100.0 * std::sqrt(sq / double(n));
}

PartCost fitPartCost(const std::vector<CostSample>& samples, const CostFitOptions& o) {
    std::vector<CostSample> layers, full;
    for (const CostSample& x : samples)
        (x.full_frame ? full : layers).push_back(x);
    // Only whole frames: the law is fitted to them and the scale stays 1.
    const bool only_full = layers.empty();
    if (only_full)
        layers = full;
    bool use_frag = o.use_frag && !samples.empty();
    double frag = 0.0, px = 0.0;
    for (const CostSample& x : samples) {
        use_frag = use_frag && x.fragments >= 0.0;
        frag += std::max(x.fragments, 0.0);
        px += x.pixels;
    }
    PartCost cost = use_frag ? fitLinear(layers, false, o.use_tri, true)
                             : fitLinear(layers, o.use_px, o.use_tri);
    if (cost.ms_per_mfrag > 0.0)
        cost.frag_per_px = px > 0.0 ? frag / px : 0.0;
    if (o.allow_power && cost.ms_per_mfrag <= 0.0) {
        const PartCost power = fitPower(layers, o.use_px, o.use_tri);
        if (power.power_coef_ms > 0.0 &&
            costResidualRmsPct(layers, power) < costResidualRmsPct(layers, cost))
            cost = power;
    }
    std::vector<double> ratio;
    for (const CostSample& x : full) {
        const double p = cost.at(x.pixels, x.triangles, x.fragments);
        if (x.ms > 0.0 && p > 0.0 && !only_full)
            ratio.push_back(x.ms / p);
    }
    if (!ratio.empty()) {
        std::sort(ratio.begin(), ratio.end());
        const size_t m = ratio.size() / 2;
        const double med = ratio.size() % 2 ? ratio[m] : 0.5 * (ratio[m - 1] + ratio[m]);
        cost.full_frame_scale = std::clamp(med, 0.01, 100.0);
    }
    return cost;
}

BitsLaw fitBitsLaw(const std::vector<BitsSample>& samples) {
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, n = 0.0;
    for (const BitsSample& s : samples) {
        if (!(s.pixels > 0.0) || !(s.bits > 0.0))
            continue;
        const double x = std::log(std::max(s.scale, 1.0));
        const double y = std::log(s.bits / s.pixels);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        n += 1.0;
    }
    BitsLaw law;
    if (n < 2.0)
        return law;
    const double den = n * sxx - sx * sx;
    law.scale_exponent =
        std::clamp(std::fabs(den) > 1e-12 ? (n * sxy - sx * sy) / den : 0.0, -4.0, 4.0);
    law.geometric_b = std::clamp(std::exp((sy - law.scale_exponent * sx) / n), 1e-6, 100.0);
    double bits = 0.0, shape = 0.0;
    for (const BitsSample& s : samples) {
        if (!(s.pixels > 0.0) || !(s.bits > 0.0))
            continue;
        bits += s.bits;
        shape += s.pixels * std::pow(std::max(s.scale, 1.0), law.scale_exponent);
    }
    law.bits_per_px_at_1 = std::clamp(shape > 0.0 ? bits / shape : law.geometric_b, 1e-6, 100.0);
    return law;
}

}  // namespace qvr
