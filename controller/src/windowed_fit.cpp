// Ridge least squares over a window, solved as a 3×3 system with coefficients kept ≥ 0 by
// dropping the inputs whose coefficient would be negative and solving again (an active set).
#include "qvr/controller/windowed_fit.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <utility>
#include <vector>

#include "qvr/core/check.h"

namespace qvr {

WindowedFit::WindowedFit(const Vec& initial, size_t window, double ridge)
    : m_theta(initial), m_window(window), m_ridge(ridge) {
    QVR_CHECK(window >= 1 && ridge > 0.0);
}

void WindowedFit::add(const Vec& x, double y, double at) {
    if (!std::isfinite(y))
        return;
    for (double v : x)
        if (!std::isfinite(v))
            return;
    m_obs.push_back({x, y, at});
    while (m_obs.size() > m_window) {
        if (std::isfinite(m_obs.front().at))
            m_recalled.push_back({m_obs.front().at, m_obs.front().y});
        m_obs.pop_front();
    }
    while (m_recalled.size() > kRecalledWindows * m_window)
        m_recalled.pop_front();
    refit();
    refitPositions();
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

struct Sample {
    const std::array<double, 3>* x;
    double y;
    double weight;
};

// Minimises Σ w·(y − θ·x)² + ridge·scale·|θ − prior|², each input scaled by its mean square so
// the pull is alike for inputs of different magnitudes. Returns the prior where the system is
// singular.
std::array<double, 3> ridgeFit(const std::vector<Sample>& samples,
                               const std::array<double, 3>& prior, double ridge) {
    std::array<double, 3> scale{};
    for (const Sample& o : samples)
        for (size_t i = 0; i < 3; ++i)
            scale[i] += (*o.x)[i] * (*o.x)[i];
    for (double& v : scale)
        v = std::max(v / double(samples.size()), 1e-12);
    std::array<double, 9> a{};
    std::array<double, 3> b{};
    for (const Sample& o : samples)
        for (size_t i = 0; i < 3; ++i) {
            b[i] += o.weight * (*o.x)[i] * o.y;
            for (size_t j = 0; j < 3; ++j)
                a[i * 3 + j] += o.weight * (*o.x)[i] * (*o.x)[j];
        }
    for (size_t i = 0; i < 3; ++i) {
        a[i * 3 + i] += ridge * scale[i];
        b[i] += ridge * scale[i] * prior[i];
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
            return prior;
        bool ok = true;
        for (size_t i = 0; i < 3; ++i)
            if (use[i] && t[i] < 0.0) {
                use[i] = false;
                ok = false;
            }
        if (ok) {
            for (size_t i = 0; i < 3; ++i)
                t[i] = silent[i] ? prior[i] : t[i];
            return t;
        }
    }
    return prior;
}

// Huber's M-estimate (Huber 1964; k = 1.345, 95% efficiency under normal noise) by two rounds
// of reweighting, the residuals' scale their median absolute value over 0.6745: one frame the
// host preempted (a 51 ms render among 0.2 ms ones at a 0.3 headset share) tilted the least-
// squares line so that a fovea half the size looked 11 ms cheaper, and e1 fled from 9.5° to 4.5°.
std::array<double, 3> robustFit(std::vector<Sample> samples, const std::array<double, 3>& prior,
                                double ridge) {
    constexpr double kHuber = 1.345;
    std::array<double, 3> theta = ridgeFit(samples, prior, ridge);
    std::vector<double> residual(samples.size());
    for (int round = 0; round < 2; ++round) {
        for (size_t k = 0; k < samples.size(); ++k) {
            const std::array<double, 3>& x = *samples[k].x;
            residual[k] =
                std::fabs(samples[k].y - (theta[0] * x[0] + theta[1] * x[1] + theta[2] * x[2]));
        }
        std::vector<double> sorted = residual;
        std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2),
                         sorted.end());
        const double scale = sorted[sorted.size() / 2] / 0.6745;
        if (!(scale > 0.0))
            break;
        for (size_t k = 0; k < samples.size(); ++k)
            samples[k].weight = std::min(1.0, kHuber * scale / std::max(residual[k], 1e-300));
        theta = ridgeFit(samples, prior, ridge);
    }
    return theta;
}

}  // namespace

void WindowedFit::refit() {
    std::vector<Sample> samples;
    for (const Obs& o : m_obs)
        samples.push_back({&o.x, o.y, 1.0});
    m_theta = robustFit(std::move(samples), m_theta, m_ridge);
}

// The position at or below `at` (one position's width of slack), or the lowest when every
// position lies above it; `end` when there are none.
std::vector<WindowedFit::Position>::const_iterator WindowedFit::atOrBelow(
    const std::vector<Position>& positions, double at) {
    if (positions.empty())
        return positions.end();
    const auto above = std::upper_bound(positions.begin(), positions.end(), at + kSamePosition,
                                        [](double v, const Position& p) { return v < p.at; });
    return above == positions.begin() ? above : std::prev(above);
}

double WindowedFit::predictAt(const Vec& x, double at) const {
    const auto p = atOrBelow(m_positions, at);
    if (p == m_positions.end())
        return predict(x);
    double y = 0.0;
    for (size_t i = 0; i < kInputs; ++i)
        y += p->theta[i] * x[i];
    return std::max(y, floorAt(at));
}

double WindowedFit::floorAt(double at) const {
    const auto above = std::upper_bound(m_floors.begin(), m_floors.end(), at + kSamePosition,
                                        [](double v, const Floor& f) { return v < f.at; });
    return above == m_floors.begin() ? -std::numeric_limits<double>::infinity()
                                     : std::prev(above)->floor;
}

std::optional<double> WindowedFit::highestPosition() const {
    std::optional<double> top;
    for (const Obs& o : m_obs)
        if (std::isfinite(o.at) && (!top || o.at > *top))
            top = o.at;
    for (const Recalled& r : m_recalled)
        if (!top || r.at > *top)
            top = r.at;
    return top;
}

void WindowedFit::refitPositions() {
    // Each position's fit is pulled toward the one that read that position at the last refit,
    // as the whole fit is toward its previous self: pulled toward the whole fit instead, a
    // cliff's line biased the cheap positions' fits by a twentieth of its error.
    const std::vector<Position> previous = std::move(m_positions);
    m_positions.clear();
    auto prior = [&](double at) -> const Vec& {
        const auto p = atOrBelow(previous, at);
        return p == previous.end() ? m_theta : p->theta;
    };
    refitFloors();
    std::vector<const Obs*> obs;
    for (const Obs& o : m_obs)
        if (std::isfinite(o.at))
            obs.push_back(&o);
    if (obs.size() < kMinAtOrBelow)
        return;
    std::stable_sort(obs.begin(), obs.end(),
                     [](const Obs* l, const Obs* r) { return l->at < r->at; });
    // Each position's fit reads the observations up to its last one, at least kMinAtOrBelow.
    for (size_t i = 0; i < obs.size(); ++i) {
        const bool last = i + 1 == obs.size() || obs[i + 1]->at - obs[i]->at > kSamePosition;
        if (!last || i + 1 < kMinAtOrBelow)
            continue;
        std::vector<Sample> samples;
        for (size_t k = 0; k <= i; ++k)
            samples.push_back({&obs[k]->x, obs[k]->y, 1.0});
        m_positions.push_back(
            {obs[i]->at, robustFit(std::move(samples), prior(obs[i]->at), m_ridge)});
    }
}

void WindowedFit::refitFloors() {
    // The window's observations, and the recalled ones at positions the window no longer holds
    // (a position the window holds reads only its fresh frames: the content moves on).
    std::vector<Recalled> seen;
    for (const Obs& o : m_obs)
        if (std::isfinite(o.at))
            seen.push_back({o.at, o.y});
    const size_t fresh = seen.size();
    for (const Recalled& r : m_recalled) {
        bool held = false;
        for (size_t i = 0; i < fresh && !held; ++i)
            held = std::fabs(seen[i].at - r.at) <= kSamePosition;
        if (!held)
            seen.push_back(r);
    }
    m_floors.clear();
    std::stable_sort(seen.begin(), seen.end(),
                     [](const Recalled& l, const Recalled& r) { return l.at < r.at; });
    // Per position: its mean and count, and the spread within positions pooled.
    struct Block {
        double at, mean, n;
        size_t first;  // pooled: the first position (index in `blocks`) it holds
    };
    std::vector<Block> blocks;
    std::vector<std::pair<size_t, size_t>> groups;
    for (size_t i = 0; i < seen.size(); ++i)
        if (groups.empty() || seen[i].at - seen[groups.back().first].at > kSamePosition)
            groups.push_back({i, i + 1});
        else
            groups.back().second = i + 1;
    double within = 0.0;
    size_t dof = 0;
    for (const auto& [b, e] : groups) {
        double sum = 0.0;
        for (size_t i = b; i < e; ++i)
            sum += seen[i].y;
        const double mean = sum / double(e - b);
        for (size_t i = b; i < e; ++i)
            within += (seen[i].y - mean) * (seen[i].y - mean);
        dof += e - b - 1;
        blocks.push_back({seen[b].at, mean, double(e - b), blocks.size()});
    }
    if (dof == 0)
        return;
    const double sd = std::sqrt(within / double(dof));
    // The cost cannot fall as the position grows: the means' isotonic regression (pool adjacent
    // violators, weighed by counts). A frame the host preempted at a position seen once (51 ms
    // among 0.2 ms renders) pools with the cheap positions above it and floors little; a cliff
    // that every position past it measures stays whole, even seen once at each.
    std::vector<Block> pooled;
    for (const Block& block : blocks) {
        pooled.push_back(block);
        while (pooled.size() >= 2 && pooled[pooled.size() - 2].mean > pooled.back().mean) {
            Block& l = pooled[pooled.size() - 2];
            const Block& r = pooled.back();
            l.mean = (l.mean * l.n + r.mean * r.n) / (l.n + r.n);
            l.n += r.n;
            pooled.pop_back();
        }
    }
    // Each position's floor: its pooled block's mean less two standard errors, never below a
    // smaller position's.
    double floor = -std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < pooled.size(); ++k) {
        const size_t end = k + 1 < pooled.size() ? pooled[k + 1].first : blocks.size();
        floor = std::max(floor, pooled[k].mean - 2.0 * sd / std::sqrt(pooled[k].n));
        for (size_t g = pooled[k].first; g < end; ++g)
            m_floors.push_back({blocks[g].at, floor});
    }
}

}  // namespace qvr
