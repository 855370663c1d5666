// Ridge least squares over a window, solved as a 3×3 system with coefficients kept ≥ 0 by
// dropping the inputs whose coefficient would be negative and solving again (an active set).
#include "qvr/controller/windowed_fit.h"

#include <algorithm>
#include <cmath>

#include "qvr/core/check.h"

namespace qvr {

WindowedFit::WindowedFit(const Vec& initial, size_t window, double ridge)
    : m_theta(initial), m_window(window), m_ridge(ridge) {
    QVR_CHECK(window >= 1 && ridge > 0.0);
}

void WindowedFit::add(const Vec& x, double y) {
    if (!std::isfinite(y))
        return;
    for (double v : x)
        if (!std::isfinite(v))
            return;
    m_obs.push_back({x, y});
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
    // Minimise Σ (y − θ·x)² + ridge·n_scale·|θ − θ_prev|², each input scaled by its mean square
    // so the pull is alike for inputs of different magnitudes.
    std::array<double, 3> scale{};
    for (const Obs& o : m_obs)
        for (size_t i = 0; i < 3; ++i)
            scale[i] += o.x[i] * o.x[i];
    for (double& v : scale)
        v = std::max(v / double(m_obs.size()), 1e-12);
    std::array<double, 9> a{};
    std::array<double, 3> b{};
    for (const Obs& o : m_obs)
        for (size_t i = 0; i < 3; ++i) {
            b[i] += o.x[i] * o.y;
            for (size_t j = 0; j < 3; ++j)
                a[i * 3 + j] += o.x[i] * o.x[j];
        }
    for (size_t i = 0; i < 3; ++i) {
        a[i * 3 + i] += m_ridge * scale[i];
        b[i] += m_ridge * scale[i] * m_theta[i];
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
            return;
        bool ok = true;
        for (size_t i = 0; i < 3; ++i)
            if (use[i] && t[i] < 0.0) {
                use[i] = false;
                ok = false;
            }
        if (ok) {
            for (size_t i = 0; i < 3; ++i)
                m_theta[i] = silent[i] ? m_theta[i] : t[i];
            return;
        }
    }
}

}  // namespace qvr
