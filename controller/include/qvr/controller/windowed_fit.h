// A small linear model y ≈ θ·x over the newest observations, refitted each time by ridge
// least squares pulled toward the previous fit, with non-negative coefficients. LIWC's runtime
// estimates of the headset's and the server's cost (docs/LIWC.md "Fits"): unlike recursive
// least squares with forgetting it cannot diverge when an input stops varying (e1 held still) —
// the unexcited directions stay where they were — and one outlier leaves the window.
#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <limits>
#include <vector>

namespace qvr {

class WindowedFit {
public:
    static constexpr size_t kInputs = 3;
    using Vec = std::array<double, kInputs>;

    // window: observations kept; ridge: the weight of the previous fit, in observations.
    WindowedFit(const Vec& initial, size_t window = 32, double ridge = 1.0);

    // at: where along a cost that cannot fall as `at` grows the observation was taken (LIWC's
    // L: the frame's e1); NaN when the cost has no such position.
    void add(const Vec& x, double y, double at = std::numeric_limits<double>::quiet_NaN());
    // The fit over the whole window.
    double predict(const Vec& x) const;
    // For a cost that cannot fall as its position grows: the fit over the observations taken at
    // positions up to `at` (at least kMinAtOrBelow of them: the fewest positions that hold as
    // many), so a cliff past `at` bends no line below it; and no less than any smaller
    // position's mean observation less two standard errors (the window's spread within a
    // position), which a line through a cliff's few observations and many cheap ones puts
    // under it. predict(x) before any observation has a position.
    double predictAt(const Vec& x, double at) const;
    const Vec& theta() const { return m_theta; }
    size_t size() const { return m_obs.size(); }
    size_t window() const { return m_window; }

    // Positions within this of a group's first are one position (e1 moves on a grid).
    static constexpr double kSamePosition = 0.05;
    static constexpr size_t kMinAtOrBelow = 8;

private:
    void refit();
    void refitPositions();
    struct Obs {
        Vec x;
        double y;
        double at;
    };
    // The fit over the observations at positions up to `at`, and the highest floor there.
    struct Position {
        double at;
        Vec theta;
        double floor;
    };
    std::deque<Obs> m_obs;
    std::vector<Position> m_positions;  // ascending `at`
    Vec m_theta;
    size_t m_window;
    double m_ridge;
};

}  // namespace qvr
