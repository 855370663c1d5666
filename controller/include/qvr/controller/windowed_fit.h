// A small linear model y ≈ θ·x over the newest observations, refitted each time by ridge
// least squares pulled toward the previous fit, with non-negative coefficients. LIWC's runtime
// estimates of the headset's and the server's cost (docs/LIWC.md "Fits"): unlike recursive
// least squares with forgetting it cannot diverge when an input stops varying (e1 held still) —
// the unexcited directions stay where they were — and one outlier leaves the window.
#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

namespace qvr {

class WindowedFit {
public:
    static constexpr size_t kInputs = 3;
    using Vec = std::array<double, kInputs>;

    // window: observations kept; ridge: the weight of the previous fit, in observations.
    WindowedFit(const Vec& initial, size_t window = 32, double ridge = 1.0);

    // `at` places the observation on a line (LIWC: the e1 it was measured at) for predictNear.
    void add(const Vec& x, double y, double at = 0.0);
    double predict(const Vec& x) const;
    // The fit near `at`: each observation weighted by the tricube of its distance over
    // `bandwidth` (none past it), pulled with the same ridge toward the window's slopes at the
    // weighted observations' level (input 0 is the constant 1). Where no observation is that
    // near, the nearest ones' fit, carried to x by their slopes. A cost with a cliff along `at`
    // (a fovea that takes in a dense model past some e1) is then not a line through both sides.
    double predictNear(const Vec& x, double at, double bandwidth) const;
    const Vec& theta() const { return m_theta; }
    size_t size() const { return m_obs.size(); }
    size_t window() const { return m_window; }

private:
    void refit();
    struct Obs {
        Vec x;
        double y;
        double at;
    };
    // The weighted observations' level and inputs' centre near `at`, and the slopes about it.
    struct LocalFit {
        double level = 0.0;
        Vec centre{};
        Vec slopes{};
    };
    std::optional<LocalFit> localFit(double at, double bandwidth) const;
    // Ridge least squares over `obs`, each weighted (empty: all 1), pulled toward `prior`, with
    // coefficients ≥ 0; false when the system is singular.
    bool solveWeighted(const std::deque<Obs>& obs, const std::vector<double>& weights,
                       const Vec& prior, Vec& out) const;
    std::deque<Obs> m_obs;
    Vec m_theta;
    size_t m_window;
    double m_ridge;
};

}  // namespace qvr
