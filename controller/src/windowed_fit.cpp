// Ridge least squares over a window, solved as a 3×3 system with coefficients kept ≥ 0 by
// dropping the inputs whose coefficient would be negative and solving again (an active set).
#include "qvr/controller/windowed_fit.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "qvr/core/check.h"

namespace qvr {

WindowedFit::WindowedFit(const Vec& initial, size_t window, double ridge)
    : m_theta(initial), m_window(window), m_ridge(ridge) {
    QVR_CHECK(window >= 1 && ridge > 0.0);
}

void WindowedFit::add(const Vec& x, double y, double at) {
    if (!std::isfinite(y) || !std::isfinite(at))
        return;
    for (double v : x)
        if (!std::isfinite(v))
            return;
    m_obs.push_back({x, y, at});
    while (m_obs.size() > m_window)
        m_obs.pop_front();
    refit();
}

double WindowedFit::predict(const Vec& x) const {
    double y = 0.0;
    for (size_t i = 0; i < kInputs; ++i)
        y += m_theta[i] * x[i];
    return y;
}

namespace {

// Solves a·t = b for the inputs in `use` (the others fixed at 0); false when singular.
bool solve(std::array<double, 9> a, std::array<double, 3> b, const std::array<bool, 3>& use,
           std::array<double, 3>& t) {
    for (size_t i = 0; i < 3; ++i)
        if (!use[i]) {
            for (size_t j = 0; j < 3; ++j)
                a[i * 3 + j] = a[j * 3 + i] = 0.0;
            a[i * 3 + i] = 1.0;
            b[i] = 0.0;
        }
    // Gaussian elimination with partial pivoting; a pivot is zero relative to the matrix's size.
    double norm = 0.0;
    for (double v : a)
        norm = std::max(norm, std::fabs(v));
    std::array<size_t, 3> row{0, 1, 2};
    for (size_t c = 0; c < 3; ++c) {
        size_t p = c;
        for (size_t r = c + 1; r < 3; ++r)
            if (std::fabs(a[row[r] * 3 + c]) > std::fabs(a[row[p] * 3 + c]))
                p = r;
        std::swap(row[c], row[p]);
        const double piv = a[row[c] * 3 + c];
        if (!(std::fabs(piv) > 1e-12 * norm))
            return false;
        for (size_t r = c + 1; r < 3; ++r) {
            const double f = a[row[r] * 3 + c] / piv;
            for (size_t k = c; k < 3; ++k)
                a[row[r] * 3 + k] -= f * a[row[c] * 3 + k];
            b[row[r]] -= f * b[row[c]];
        }
    }
    for (size_t c = 3; c-- > 0;) {
        double v = b[row[c]];
        for (size_t k = c + 1; k < 3; ++k)
            v -= a[row[c] * 3 + k] * t[k];
        t[c] = v / a[row[c] * 3 + c];
    }
    return true;
}

}  // namespace

void WindowedFit::refit() {
    Vec t = m_theta;
    if (solveWeighted(m_obs, {}, m_theta, t))
        m_theta = t;
}

double WindowedFit::predictNear(const Vec& x, double at, double bandwidth) const {
    if (m_obs.empty() || !(bandwidth > 0.0))
        return predict(x);
    // No observation within `bandwidth`: the nearest ones' level and slopes, carried to `at` by
    // the inputs' difference (the window's whole fit has another level, and comparing a
    // candidate read one way with one read the other made a step between them).
    std::optional<LocalFit> fit = localFit(at, bandwidth);
    if (!fit) {
        double nearest = m_obs.front().at;
        for (const Obs& o : m_obs)
            if (std::fabs(o.at - at) < std::fabs(nearest - at))
                nearest = o.at;
        fit = localFit(nearest, bandwidth);
    }
    if (!fit)
        return predict(x);
    double y = fit->level;
    for (size_t i = 0; i < kInputs; ++i)
        y += fit->slopes[i] * (x[i] - fit->centre[i]);
    return y;
}

std::optional<WindowedFit::LocalFit> WindowedFit::localFit(double at, double bandwidth) const {
    // Tricube weights (LOESS, Cleveland 1979): an observation past `bandwidth` has none, so the
    // far side of a cliff does not lever the line near `at`.
    std::vector<double> w;
    w.reserve(m_obs.size());
    LocalFit fit;
    double total = 0.0;
    for (const Obs& o : m_obs) {
        const double d = std::min(1.0, std::fabs(o.at - at) / bandwidth);
        const double c = 1.0 - d * d * d;
        w.push_back(c * c * c);
        total += w.back();
        fit.level += w.back() * o.y;
        for (size_t i = 0; i < kInputs; ++i)
            fit.centre[i] += w.back() * o.x[i];
    }
    if (!(total > 0.0))
        return std::nullopt;
    fit.level /= total;
    for (double& v : fit.centre)
        v /= total;
    // The level of the frames near `at` and the slopes fitted about it, pulled toward the
    // window's: centred, the constant input is 0 in every observation and drops out.
    std::deque<Obs> centred;
    for (const Obs& o : m_obs) {
        Obs c = o;
        for (size_t i = 0; i < kInputs; ++i)
            c.x[i] -= fit.centre[i];
        c.y -= fit.level;
        centred.push_back(c);
    }
    fit.slopes = m_theta;
    if (!solveWeighted(centred, w, m_theta, fit.slopes))
        return std::nullopt;
    return fit;
}

bool WindowedFit::solveWeighted(const std::deque<Obs>& obs, const std::vector<double>& weights,
                                const Vec& prior, Vec& out) const {
    // Minimise Σ w·(y − θ·x)² + ridge·n_scale·|θ − prior|², each input scaled by its weighted
    // mean square: the pull is worth `ridge` observations like those weighed, alike for inputs of
    // different magnitudes.
    std::array<double, 3> scale{};
    double total = 0.0;
    for (size_t k = 0; k < obs.size(); ++k) {
        const double w = weights.empty() ? 1.0 : weights[k];
        total += w;
        for (size_t i = 0; i < 3; ++i)
            scale[i] += w * obs[k].x[i] * obs[k].x[i];
    }
    for (double& v : scale)
        v = std::max(v / std::max(total, 1e-12), 1e-12);
    std::array<double, 9> a{};
    std::array<double, 3> b{};
    for (size_t k = 0; k < obs.size(); ++k) {
        const Obs& o = obs[k];
        const double w = weights.empty() ? 1.0 : weights[k];
        for (size_t i = 0; i < 3; ++i) {
            b[i] += w * o.x[i] * o.y;
            for (size_t j = 0; j < 3; ++j)
                a[i * 3 + j] += w * o.x[i] * o.x[j];
        }
    }
    for (size_t i = 0; i < 3; ++i) {
        a[i * 3 + i] += m_ridge * scale[i];
        b[i] += m_ridge * scale[i] * prior[i];
    }
    // An input that was 0 in every observation says nothing about its coefficient: keep it.
    std::array<bool, 3> use{true, true, true};
    std::array<bool, 3> silent{};
    for (size_t i = 0; i < 3; ++i)
        silent[i] = scale[i] <= 1e-12;
    for (size_t i = 0; i < 3; ++i)
        if (silent[i])
            use[i] = false;
    for (int round = 0; round < 3; ++round) {
        std::array<double, 3> t{};
        if (!solve(a, b, use, t))
            return false;
        bool ok = true;
        for (size_t i = 0; i < 3; ++i)
            if (use[i] && t[i] < 0.0) {
                use[i] = false;
                ok = false;
            }
        if (ok) {
            for (size_t i = 0; i < 3; ++i)
                out[i] = silent[i] ? prior[i] : t[i];
            return true;
        }
    }
    return false;
}

}  // namespace qvr
