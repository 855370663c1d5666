// One-dimensional minimisation by golden-section search, for the searches of the layer plan
// (e2*, Eq. 1) and the oracle policy: both scan coarsely first, then refine one bracket.
#pragma once

namespace qvr {

// Narrows [lo, hi] around a minimum of f, assumed unimodal inside it, for at most max_iters
// steps or until the bracket is narrower than tolerance; returns the bracket's midpoint.
template <typename F>
double goldenSectionMin(F&& f, double lo, double hi, int max_iters, double tolerance = 0.0) {
    constexpr double kInvPhi = 0.6180339887498949;
    double a = hi - kInvPhi * (hi - lo);
    double b = lo + kInvPhi * (hi - lo);
    double fa = f(a);
    double fb = f(b);
    for (int i = 0; i < max_iters && hi - lo > tolerance; ++i) {
        if (fa < fb) {
            hi = b;
            b = a;
            fb = fa;
            a = hi - kInvPhi * (hi - lo);
            fa = f(a);
        } else {
            lo = a;
            a = b;
            fa = fb;
            b = lo + kInvPhi * (hi - lo);
            fb = f(b);
        }
    }
    return 0.5 * (lo + hi);
}

}  // namespace qvr
