// A small linear model y ≈ θ·x over the newest observations, refitted each time by ridge
// least squares pulled toward the previous fit, with non-negative coefficients. LIWC's runtime
// estimates of the headset's and the server's cost (docs/LIWC.md "Fits"): unlike recursive
// least squares with forgetting it cannot diverge when an input stops varying (e1 held still) —
// the unexcited directions stay where they were — and one outlier leaves the window.
#pragma once

#include <array>
#include <cstddef>
#include <deque>

namespace qvr {

class WindowedFit {
public:
    static constexpr size_t kInputs = 3;
    using Vec = std::array<double, kInputs>;

    // window: observations kept; ridge: the weight of the previous fit, in observations.
    WindowedFit(const Vec& initial, size_t window = 32, double ridge = 1.0);

    void add(const Vec& x, double y);
    double predict(const Vec& x) const;
    const Vec& theta() const { return m_theta; }
    size_t size() const { return m_obs.size(); }
    size_t window() const { return m_window; }

private:
    void refit();
    struct Obs {
        Vec x;
        double y;
    };
    std::deque<Obs> m_obs;
    Vec m_theta;
    size_t m_window;
    double m_ridge;
};

}  // namespace qvr
