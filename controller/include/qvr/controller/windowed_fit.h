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
#include <optional>
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
    // many), so a cliff past `at` bends no line below it; and no less than the floor at `at`:
    // the isotonic (non-decreasing) regression of the positions' mean observations, less two
    // standard errors (the spread within a position), over the window and the positions
    // recalled from the kRecalledWindows windows before it — a line through a cliff's few
    // observations and many cheap ones puts it under the cliff, and a cliff that left the
    // window drew e1 back to it every window. predict(x) before any observation has a position.
    double predictAt(const Vec& x, double at) const;
    // The largest position observed in the window or recalled: above it predictAt extrapolates.
    std::optional<double> highestPosition() const;
    const Vec& theta() const { return m_theta; }
    size_t size() const { return m_obs.size(); }
    size_t window() const { return m_window; }

    // Positions within this of a group's first are one position (e1 moves on a grid).
    static constexpr double kSamePosition = 0.05;
    static constexpr size_t kMinAtOrBelow = 8;
    // Windows of positions and costs kept for the floor after they leave the window.
    static constexpr size_t kRecalledWindows = 3;

private:
    void refit();
    void refitPositions();
    struct Obs {
        Vec x;
        double y;
        double at;
    };
    void refitFloors();
    double floorAt(double at) const;
    // The fit over the observations at positions up to `at`.
    struct Position {
        double at;
        Vec theta;
    };
    struct Recalled {
        double at;
        double y;
    };
    struct Floor {
        double at;
        double floor;
    };
    static std::vector<Position>::const_iterator atOrBelow(const std::vector<Position>& positions,
                                                           double at);
    std::deque<Obs> m_obs;
    std::vector<Position> m_positions;  // ascending `at`
    std::deque<Recalled> m_recalled;    // observations with a position that left the window
    std::vector<Floor> m_floors;        // ascending `at`, non-decreasing
    Vec m_theta;
    size_t m_window;
    double m_ridge;
};

}  // namespace qvr
