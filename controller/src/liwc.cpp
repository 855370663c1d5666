// LIWC (paper §4.1, Eq. 2). The decision is a handful of table lookups and multiply-adds per
// delta tag — the work the paper puts in a small accelerator; here it runs in well under a
// microsecond on a CPU (bench/liwc_bench.cpp).
#include "qvr/controller/liwc.h"

#include <algorithm>
#include <cmath>

namespace qvr {

LiwcPolicy::LiwcPolicy(const WorkloadHeader& header, LiwcConfig config)
    : m_header(header),
      m_config(config),
      m_sizes(header.profile, std::min(90.0, config.e1_max_deg)),
      m_gpu_theta{0.0, 1e5 / config.gpu_triangles_per_ms_initial,
                  1e5 / config.gpu_pixels_per_ms_initial},
      m_gpu_cov{1, 0, 0, 0, 1, 0, 0, 0, 1},

      m_throughput_bps(config.throughput_bps_initial),
      m_log_bits_at_1(std::log(config.bits_per_pixel_initial)),
      m_bits_exponent(config.bits_scale_exponent_initial),
      m_local_fit(
          {0.0, 1e5 / config.gpu_triangles_per_ms_initial, 1e5 / config.gpu_pixels_per_ms_initial}),
      m_server_fit({0.0, 0.0, 0.0}),
      m_e1_deg(config.e1_initial_deg) {
    QVR_CHECK(config.max_delta_deg == 5);  // the table's tags are −5…+5
    QVR_CHECK(config.alpha > 0.0f && config.alpha <= 1.0f);
    QVR_CHECK(config.rate_ema > 0.0 && config.rate_ema <= 1.0);
}

double LiwcPolicy::bitsPerPixelAt(double scale) const {
    return std::exp(m_log_bits_at_1 + m_bits_exponent * std::log(std::max(1.0, scale)));
}

double LiwcPolicy::gpuTrianglesPerMs() const {
    return 1e5 / std::max(1e-9, m_gpu_theta[1]);
}
double LiwcPolicy::gpuPixelsPerMs() const {
    return 1e5 / std::max(1e-9, m_gpu_theta[2]);
}

void LiwcPolicy::prepareFrame(const WorkloadFrame& frame) const {
    m_cover_deg = m_sizes.coverDeg(frame.gaze);
    m_gaze = frame.gaze;
    auto prefix = [](const std::vector<double>& rings, std::vector<double>& out) {
        out.resize(rings.size() + 1);
        out[0] = 0.0;
        for (size_t k = 0; k < rings.size(); ++k)
            out[k + 1] = out[k] + rings[k];
    };
    prefix(frame.triangles_per_ring, m_prefix_tris);
    prefix(frame.pixels_per_ring, m_prefix_pixels);
}

double LiwcPolicy::prefixAt(const std::vector<double>& prefix, double ring_deg, double e_deg) {
    // The same sum as sumWithinDeg(), in O(1) from prefix sums.
    const size_t rings = prefix.size() - 1;
    if (e_deg <= 0.0 || rings == 0)
        return 0.0;
    const double r = e_deg / ring_deg;
    const size_t whole = static_cast<size_t>(r);
    if (whole >= rings)
        return prefix[rings];
    return prefix[whole] + (prefix[whole + 1] - prefix[whole]) * (r - static_cast<double>(whole));
}

double LiwcPolicy::localMs(double e1_deg) const {
    // Eq. 2: the fovea cone's work over the GPU's rate. The triangle count is the "hardware
    // intermediate data" available after geometry setup, before rendering; the rate is split
    // into a triangle rate and a fragment rate (plus a fixed cost) because a single
    // triangles-per-millisecond figure mispredicts by a third whenever a saccade moves the
    // fovea between dense geometry and plain surfaces (docs/LIWC.md).
    const double e = e1_deg >= m_cover_deg ? 1e9 : e1_deg;
    const double tris = prefixAt(m_prefix_tris, m_header.ring_deg, e);
    const double pixels = prefixAt(m_prefix_pixels, m_header.ring_deg, e);
    if (m_config.frame_period_objective) {
        // A larger fovea renders a superset of a smaller one's pixels, so L's fit at e1 reads
        // the frames at e1 or below: a fovea that takes in a dense model past some e1 costs tens
        // of ms more there, and one line through both sides put L below that cliff at 2-3x what
        // it measured, so e1 fled to 3.5° where 10° was best (docs/LIWC.md "Fits").
        const double render = renderMs(tris, pixels, e1_deg);
        if (!m_render_apart || m_local_rest.empty())
            return render;
        const double rest = m_local_rest_sum / double(m_local_rest.size());
        if (m_headset_share >= 1.0)
            return rest + render;
        // Under a CFS quota the rest holds the throttling the current e1's work brought on:
        // the CPU a candidate costs more or less than the current e1 (its render, its
        // periphery's decode) moves the busy time by 1/s of it, s the quota's share.
        const double extra = render + decodeMs(e1_deg) - headsetCpuMs(m_e1_deg);
        return std::max(render, rest + render + (1.0 / m_headset_share - 1.0) * extra);
    }
    return std::max(0.0,
                    m_gpu_theta[0] + m_gpu_theta[1] * tris * 1e-5 + m_gpu_theta[2] * pixels * 1e-5);
}

double LiwcPolicy::peripheryBits(const Gaze& gaze, double e1_deg) const {
    const PeripheryShape p = m_sizes.lookup(gaze, e1_deg);
    return 2.0 * (p.middle_pixels * layerBitsPerPixel(kMiddle, p.s1) +
                  p.outer_pixels * layerBitsPerPixel(kOuter, p.s2));
}

double LiwcPolicy::layerBitsPerPixel(int layer, double scale) const {
    return bitsPerPixelAt(scale) * std::exp(m_layer_log_ratio[static_cast<size_t>(layer)]);
}

double LiwcPolicy::remoteMs(const Gaze& gaze, double e1_deg) const {
    // Eq. 2: the periphery's bytes over the throughput measured from acknowledgements.
    if (e1_deg >= m_cover_deg)
        return 0.0;
    return m_remote_base_ms + peripheryBits(gaze, e1_deg) / m_throughput_bps * 1000.0;
}

double LiwcPolicy::renderMs(double tris, double pixels, double e1_deg) const {
    return std::max(0.0, m_local_fit.predictAt({1.0, tris * 1e-5, pixels * 1e-5}, e1_deg));
}

double LiwcPolicy::headsetCpuMs(double e1_deg) const {
    const double e = e1_deg >= m_cover_deg ? 1e9 : e1_deg;
    return renderMs(prefixAt(m_prefix_tris, m_header.ring_deg, e),
                    prefixAt(m_prefix_pixels, m_header.ring_deg, e), e1_deg) +
           decodeMs(e1_deg);
}

double LiwcPolicy::decodeMs(double e1_deg) const {
    if (e1_deg >= m_cover_deg || m_decode_fit.size() == 0)
        return 0.0;
    const PeripheryShape p = m_sizes.lookup(m_gaze, e1_deg);
    return std::max(0.0, m_decode_fit.predict(
                             {1.0, 2.0 * p.middle_pixels * 1e-5, 2.0 * p.outer_pixels * 1e-5}));
}

void LiwcPolicy::setHeadsetShare(double share) {
    m_headset_share = std::isfinite(share) && share > 0.0 && share <= 1.0 ? share : 1.0;
}

void LiwcPolicy::setLinkEstimate(double throughput_bps) {
    if (throughput_bps > 0.0 && std::isfinite(throughput_bps))
        m_link_bps = throughput_bps;
}

double LiwcPolicy::linkBps() const {
    if (m_config.reactive || m_link_bps <= 0.0)
        return m_throughput_bps;
    if (m_frames_without_link == 0)
        return m_link_bps;
    // Frames that sent nothing teach nothing of the link, and an estimate too low to send
    // anything would hold forever: it relaxes (in log space) toward the prior, so the period
    // objective tries the link again and a fresh sample replaces it.
    const double w =
        1.0 - std::exp(-double(m_frames_without_link) / (kStaleLinkFrames * m_stale_link_backoff));
    const double prior = std::max(m_link_bps, m_config.throughput_bps_initial);
    return std::exp((1.0 - w) * std::log(m_link_bps) + w * std::log(prior));
}

double LiwcPolicy::peripheryTriangles(double e1_deg) const {
    const size_t rings = m_prefix_tris.size() - 1;
    const double total = rings > 0 ? m_prefix_tris[rings] : 0.0;
    if (e1_deg >= m_cover_deg)
        return 0.0;
    return std::max(0.0, total - prefixAt(m_prefix_tris, m_header.ring_deg, e1_deg));
}

double LiwcPolicy::peripheryPixels(const Gaze& gaze, double e1_deg) const {
    if (e1_deg >= m_cover_deg)
        return 0.0;
    const PeripheryShape p = m_sizes.lookup(gaze, e1_deg);
    return 2.0 * (p.middle_pixels + p.outer_pixels);
}

double LiwcPolicy::transmissionMs(const Gaze& gaze, double e1_deg) const {
    if (e1_deg >= m_cover_deg)
        return 0.0;
    const double bps = linkBps();
    return peripheryBits(gaze, e1_deg) / std::max(1.0, bps) * 1000.0;
}

void LiwcPolicy::MoveMeter::add(bool was_moved, double e1_deg, double value) {
    if (was_moved) {
        m_pending = {e1_deg, value};
        return;
    }
    // Against the next frame that held the moved frame's e1: both at the same fovea, so what
    // the model would have mispredicted at a new e1 cancels, and only the move's own cost is
    // left (measured against the model, a move to an e1 the fits had not seen read their
    // extrapolation error as the move's: 30x on the UMTS trace, every later move priced out).
    if (m_pending && std::fabs(m_pending->e1_deg - e1_deg) <= 0.05 && value > 0.0) {
        const double e = m_pending->value / value - 1.0;  // signed: noise averages out
        m_extra = m_have ? (1.0 - kMoveEmaWeight) * m_extra + kMoveEmaWeight * e : e;
        m_have = true;
    }
    m_pending.reset();
}

LiwcPolicy::MoveCost LiwcPolicy::moveCost() const {
    // Spread over the frames a chosen e1 is measured to hold, or has held since the last move if
    // that is longer (else a cost that stops moves would never see them grow).
    const double frames = std::max({1.0, m_frames_between_moves, double(m_frames_since_move)});
    return {m_move_bits.extra() / frames, m_move_server.extra() / frames};
}

Decision LiwcPolicy::decidePeriod(const WorkloadFrame& frame, double lo, double hi) {
    // With frames in flight each stage works on its own frame: the period is the slowest stage's
    // — the headset's L, the server's S, the link's X — and no shorter than the remote chain
    // S + X over the frames in flight (one frame in flight: the headset renders its fovea while
    // the server and the link work in turn, max(L, S + X)). Minimise it over a grid of
    // ±max_delta in half degrees; the table's learned offset corrects the remote chain S + X.
    struct Eval {
        double e1 = 0.0, local = 0.0, server = 0.0, link = 0.0, chain = 0.0, period = 0.0;
        double latency = 0.0;
        double score = 0.0;  // the period plus, for a move, its byte cost
        double triangles = 0.0, pixels = 0.0;
        double remote() const { return server + link; }
    };
    // The table's offset for R is read at the bucket of the current e1 for every candidate: that
    // cell is refreshed by every observation, while the cells of buckets e1 passed through
    // early keep the cold start's errors and, added to lower candidates, pinned e1 high when R
    // does not fall with it (tests/controller: DriftsToTheSmallestFovea...). What the table
    // then carries is R's motion-correlated error near the operating point.
    const double offset = remoteOffsetMs(m_motion, LiwcTable::bucketOf(m_e1_deg));
    const double in_flight = std::max(1, m_config.frames_in_flight);
    const MoveCost move_cost = moveCost();
    auto evaluate = [&](double e) {
        Eval v;
        v.e1 = e;
        v.local = localMs(e);
        v.triangles = peripheryTriangles(e);
        v.pixels = peripheryPixels(frame.gaze, e);
        if (e < m_cover_deg) {
            v.server =
                std::max(0.0, m_server_fit.predict({1.0, v.triangles * 1e-5, v.pixels * 1e-5}));
            v.link = transmissionMs(frame.gaze, e);
        }
        // The table's offset corrects the remote chain — request to last packet — not the link's
        // stage: the server sends each layer as it is encoded, so the chain is shorter than S + X,
        // and read into X that overlap made a 1.33 Mbit/s link look free (X 11.5 ms, offset
        // -11 ms: e1 chosen by L against S alone, 12.5° where the link-bound best was 15-20°).
        v.chain = e < m_cover_deg ? std::max(0.0, v.remote() + offset) : 0.0;
        v.latency = v.local + v.chain;
        v.period = std::max({v.local, v.server, v.link, v.chain / in_flight});
        // A move re-sizes the encoders' canvases: the extra bytes and server time it was
        // measured to cost, spread over the frames a chosen e1 holds.
        const bool moves = std::fabs(e - m_e1_deg) > 1e-6;
        v.score = v.period + (moves ? move_cost.link * v.link + move_cost.server * v.server : 0.0);
        return v;
    };
    // Start from staying where we are: another candidate must shorten the period, or at an
    // equal period the latency, by more than period_tie to move e1 (hysteresis against the
    // frame-to-frame noise of the measurements, and against the server's fit, which sees little
    // of S's slope while e1 holds: a more eager latency tie walked e1 down on the default run
    // while the server was the slowest stage).
    const double step = 0.5;
    const int steps = 2 * m_config.max_delta_deg * 2;
    const double top = std::max(lo, hi);
    const double trusted = std::max(lo, trustedTop(hi));
    Eval best = evaluate(std::clamp(m_e1_deg, lo, trusted));
    for (int k = 0; k <= steps; ++k) {
        const Eval v =
            evaluate(std::clamp(m_e1_deg - m_config.max_delta_deg + k * step, lo, trusted));
        const double tie = m_config.period_tie * std::max(best.score, v.score);
        if (v.score < best.score - tie ||
            (std::fabs(v.score - best.score) <= tie &&
             v.latency < best.latency - m_config.period_tie * best.latency))
            best = v;
    }
    // The window sees only ±max_delta. Where the period is flat across it — a link so slow
    // that R exceeds L at every e1 short of the whole view, so each step of the window saves
    // less than the tie — the search would stay put although the all-local cover (or another
    // far e1) is much faster. Look over the whole range on a coarse grid as well, and when a
    // far e1 beats the window by more than the tie, head for it one window step a frame.
    {
        Eval far = best;
        for (double e = lo;; e = std::min(top, e + kFarStepDeg)) {
            const Eval v = evaluate(e);
            if (v.score < far.score)
                far = v;
            if (e >= top)
                break;
        }
        if (far.score < best.score - m_config.period_tie * best.score) {
            const double toward = std::clamp(far.e1, m_e1_deg - m_config.max_delta_deg,
                                             m_e1_deg + m_config.max_delta_deg);
            best = evaluate(std::clamp(toward, lo, trusted));
        }
    }
    m_e1_deg = best.e1;
    Decision d;
    d.e1_deg = best.e1;
    d.t_local_pred_ms = best.local;
    d.t_remote_pred_ms = best.chain;
    remember(d);
    m_pending.back().periphery_triangles = best.triangles;
    m_pending.back().periphery_pixels = best.pixels;
    // Here the table learns what the model (without the offset) mispredicted of T_remote alone:
    // T_local has its own fit, refreshed every frame, and an offset learned from the imbalance
    // would move R by L's error, which the period cannot absorb.
    m_pending.back().model_imbalance_ms = best.remote();
    return d;
}

double LiwcPolicy::trustedTop(double hi) const {
    // Above the largest e1 measured, L is the fit's extrapolation, blind to a dense model that
    // enters the fovea there. With decisions in flight unmeasured the far search walked 12° to
    // 37° in five frames, one window step a frame, into a 60 ms render (tests/controller: a
    // cliff in the fovea render). Candidates go at most one window step past what was measured.
    const std::optional<double> measured = m_local_fit.highestPosition();
    return measured ? std::min(hi, *measured + m_config.max_delta_deg) : hi;
}

double LiwcPolicy::predictLocalMs(const WorkloadFrame& frame, double e1_deg) const {
    prepareFrame(frame);
    return localMs(e1_deg);
}

double LiwcPolicy::predictRemoteMs(const WorkloadFrame& frame, double e1_deg) const {
    prepareFrame(frame);
    return remoteMs(frame.gaze, e1_deg);
}

Decision LiwcPolicy::decide(const WorkloadFrame& frame) {
    m_motion = m_have_previous ? encodeMotion(m_previous_head, frame.head, m_previous_gaze,
                                              frame.gaze, m_config.motion)
                               : 0;
    m_previous_head = frame.head;
    m_previous_gaze = frame.gaze;
    m_have_previous = true;

    if (m_config.reactive) {
        // Software sees a frame's triangles only once it has rendered: decide with the rings
        // of the newest observed frame.
        m_seen.push_back({frame.index, frame.triangles_per_ring, frame.pixels_per_ring});
        while (m_seen.size() > kMaxPendingDecisions)
            m_seen.pop_front();
        if (m_reactive_rings) {
            WorkloadFrame old = frame;
            old.triangles_per_ring = m_reactive_rings->triangles_per_ring;
            old.pixels_per_ring = m_reactive_rings->pixels_per_ring;
            prepareFrame(old);
        } else {
            prepareFrame(frame);
        }
    } else {
        prepareFrame(frame);
    }
    const double hi = std::min(m_config.e1_max_deg, m_cover_deg);
    const double lo = m_config.e1_min_deg;
    // Nothing measured yet: the first frame runs at the initial e1 (Fig. 14 starts at 5°). With
    // the period objective e1 also holds until a frame that held, timed, has been observed:
    // before it, the costs are the cold-start priors (1 bit a pixel, 20-50x a P-frame's; a
    // mobile GPU's rates) and the session's opening key frames, no basis for a move.
    const bool cold = m_first_decision || (m_config.frame_period_objective && !m_seen_held_frame);
    if (cold) {
        if (m_first_decision)
            m_e1_deg = std::clamp(m_config.e1_initial_deg, lo, std::max(lo, hi));
        m_first_decision = false;
        Decision d{m_e1_deg, localMs(m_e1_deg), remoteMs(frame.gaze, m_e1_deg)};
        remember(d);
        if (m_config.frame_period_objective)
            m_pending.back().model_imbalance_ms = d.t_remote_pred_ms;
        m_pending.back().periphery_triangles = peripheryTriangles(m_e1_deg);
        m_pending.back().periphery_pixels = peripheryPixels(frame.gaze, m_e1_deg);
        return d;
    }
    if (m_config.frame_period_objective)
        return decidePeriod(frame, lo, hi);
    // One candidate per delta tag; the table's offset is indexed by the candidate's
    // eccentricity bucket under the current motion.
    int best = 0;
    for (int i = 0; i < 11; ++i) {
        LiwcCandidate& c = m_candidates[static_cast<size_t>(i)];
        c.delta_deg = i - 5;
        c.e1_deg = std::clamp(m_e1_deg + c.delta_deg, lo, std::max(lo, hi));
        c.t_local_pred_ms = localMs(c.e1_deg);
        c.t_remote_pred_ms = remoteMs(frame.gaze, c.e1_deg);
        c.offset_ms = m_table.offsetMs(m_motion, LiwcTable::bucketOf(c.e1_deg));
        if (std::fabs(c.imbalanceMs()) <
            std::fabs(m_candidates[static_cast<size_t>(best)].imbalanceMs()))
            best = i;
    }
    double chosen = m_candidates[static_cast<size_t>(best)].e1_deg;
    if (m_config.interpolate) {
        // The balance point usually lies between two tags: interpolate linearly between the
        // best tag and the neighbour on the other side of zero imbalance.
        const double ib = m_candidates[static_cast<size_t>(best)].imbalanceMs();
        for (int n : {best - 1, best + 1}) {
            if (n < 0 || n > 10)
                continue;
            const LiwcCandidate& c = m_candidates[static_cast<size_t>(n)];
            const double in = c.imbalanceMs();
            if ((ib > 0) != (in > 0) && ib != in) {
                const double t = ib / (ib - in);
                chosen = m_candidates[static_cast<size_t>(best)].e1_deg +
                         t * (c.e1_deg - m_candidates[static_cast<size_t>(best)].e1_deg);
                break;
            }
        }
    }
    m_e1_deg = chosen;
    Decision d;
    d.e1_deg = chosen;
    d.t_local_pred_ms = localMs(chosen);
    d.t_remote_pred_ms = remoteMs(frame.gaze, chosen);
    remember(d);
    return d;
}

void LiwcPolicy::remember(const Decision& d) {
    m_pending.push_back(PendingDecision{m_motion, LiwcTable::bucketOf(d.e1_deg),
                                        d.t_remote_pred_ms - d.t_local_pred_ms});
    // A caller that decides without ever observing must not grow this without bound.
    while (m_pending.size() > kMaxPendingDecisions)
        m_pending.pop_front();
}

void LiwcPolicy::observe(const FrameMeasurement& m) {
    // The table learns what the model mispredicted for this motion and eccentricity: the
    // measured imbalance against the one Eq. 2 predicted with the pre-frame estimates. During
    // warm-up the estimates are still far off and their error is not the motion's.
    // Observations arrive in frame order, so this one belongs to the oldest open decision.
    // A frame whose e1 moved carries the move's bytes (a key frame, a new canvas): what it
    // cost is learned apart (learnMoveCost), and the table and the bits law, which predict a
    // frame that holds, learn from the others (frame_period_objective).
    // The session's first frame: its remote chain opened the encoders and its link carried their
    // key frames, so it teaches neither the server's fit nor the bits law.
    const bool opening = m_observed == 0;
    const FrameKind kind =
        m_config.frame_period_objective
            ? learnMoveCost(m, m.middle_pixels * layerBitsPerPixel(kMiddle, m.s1) +
                                   m.outer_pixels * layerBitsPerPixel(kOuter, m.s2))
            : FrameKind::kHeld;
    const bool moved_apart = kind != FrameKind::kHeld;
    // A held frame's new canvas shows S no slope, only a key frame's encode.
    const bool late_canvas = kind == FrameKind::kLateCanvas;
    // The cold start ends on a held frame that also taught the fits: a start-up frame (no
    // timing, isStartUpFrame) held at the initial e1 left L at its prior, a mobile GPU's rate,
    // and on a slow headset that prior sent e1 to 25-30° for ten frames (rate:1, docs/LIWC.md).
    // A late periphery is timed too: the link is slower than the wait.
    // A withheld one is not: the remote chain has said nothing of it.
    const bool timed =
        m.t_local_ms > 0.0 && !m.periphery_withheld &&
        (m.t_remote_ms > 0.0 || m.periphery_late || m.middle_bytes + m.outer_bytes <= 0.0);
    m_seen_held_frame = m_seen_held_frame || (kind == FrameKind::kHeld && timed);
    std::optional<PendingDecision> decided;
    if (!m_pending.empty()) {
        const PendingDecision p = m_pending.front();
        decided = p;
        m_pending.pop_front();
        // A withheld periphery has no T_remote to learn from.
        if (m_observed >= m_config.table_warmup_frames && !moved_apart && !m.periphery_withheld) {
            const double measured =
                m_config.frame_period_objective ? m.t_remote_ms : m.t_remote_ms - m.t_local_ms;
            const double delta = measured - p.model_imbalance_ms;
            foldRemoteOffset(p.motion, p.bucket, delta);
        }
    }
    if (m_config.reactive) {
        while (!m_seen.empty() && m_seen.front().index < m.index)
            m_seen.pop_front();
        if (!m_seen.empty() && m_seen.front().index == m.index) {
            m_reactive_rings = m_seen.front();
            m_seen.pop_front();
        }
    }
    ++m_observed;
    // A frame that sent nothing says nothing of the link; one whose periphery came late does
    // (its acks bring the estimate that explains it).
    const bool link_seen = m.middle_bytes + m.outer_bytes > 0.0 || m.periphery_late;
    // A try of the link after frames without one that came late again (the link is still down)
    // doubles the wait before the next (a late periphery stalls its frame up to the wait limit);
    // one on time resets it.
    if (link_seen && m.periphery_late && m_frames_without_link > 0)
        m_stale_link_backoff = std::min(kMaxStaleLinkBackoff, 2.0 * m_stale_link_backoff);
    else if (link_seen && !m.periphery_late)
        m_stale_link_backoff = 1.0;
    // A withheld one did not try the link: the requests before it were still on it.
    if (!m.periphery_withheld)
        m_frames_without_link = link_seen ? 0 : m_frames_without_link + 1;
    const double b = m_config.rate_ema;
    if (m.t_local_ms > 0.0) {
        if (m_config.frame_period_objective)
            learnLocal(m);
        else
            updateGpuRates(m.triangles_local, m.pixels_local, m.t_local_ms);
    }
    // A held frame's periphery, all in on time: its decode (a move's key frames decode longer).
    if (m_config.frame_period_objective && kind == FrameKind::kHeld && m.t_decode_ms > 0.0 &&
        !m.periphery_late && !m.periphery_withheld)
        m_decode_fit.add({1.0, m.middle_pixels * 1e-5, m.outer_pixels * 1e-5}, m.t_decode_ms);
    if (m.throughput_bps > 0.0)
        m_throughput_bps = (1.0 - b) * m_throughput_bps + b * m.throughput_bps;
    if (m_config.frame_period_objective && decided && m.t_remote_ms > 0.0) {
        // What the server took of the frame, against what it had to draw: as the server said
        // (its streams' headers), else, from a server that says nothing, inferred from T_remote
        // (serverMsOf, which reads the previous arrival before it is replaced below). Inferred,
        // S took every wait T_remote's link part had beyond the acks' estimate: on a bursty
        // 2 Mbit/s trace 45-50 ms against the server's 16, and e1 sat 6° above the best fixed
        // one to spare it. Once the server has said it, a frame that did not (late) teaches S
        // nothing.
        m_server_says = m_server_says || m.server_ms > 0.0;
        const double sent_bits = (m.middle_bytes + m.outer_bytes) * 8.0;
        const double bps = linkBps();
        const double server_ms = m.server_ms > 0.0 ? m.server_ms
                                 : m_server_says   ? 0.0
                                                   : serverMsOf(m, sent_bits / bps * 1000.0);
        const std::array<double, 3> x{1.0, decided->periphery_triangles * 1e-5,
                                      decided->periphery_pixels * 1e-5};
        // A moved frame's server time (its new canvases' key frames) over the next held frame's
        // at its e1: what a move costs the server. Moved frames stay in the fit: they are the
        // frames that show S's slope (left out, a walk of e1 across the range taught the fit
        // nothing and left a stale slope). A server time of 0 is the link estimate's, not the
        // server's: T_remote held nothing beyond the transmission it predicts (the runtime's
        // first frames, before the acks' estimate has settled), so it teaches neither.
        if (!opening && server_ms > 0.0)
            m_move_server.add(moved_apart, m.e1_deg, server_ms);
        if (!opening && !late_canvas && server_ms > 0.0)
            m_server_fit.add(x, server_ms);
    } else if (m_config.learn_remote_base && m.t_remote_ms > 0.0) {
        const double sent_bits = (m.middle_bytes + m.outer_bytes) * 8.0;
        const double transmission_ms = sent_bits / m_throughput_bps * 1000.0;
        const double rest = std::max(0.0, m.t_remote_ms - transmission_ms);
        m_remote_base_ms = (1.0 - b) * m_remote_base_ms + b * rest;
    }
    // What a late frame carried by its wait limit is part of its periphery: its sizes teach the
    // bits law once the rest has come (observeLateArrival).
    if (m.periphery_late && kind == FrameKind::kHeld) {
        m_late.push_back({m.index, m.middle_pixels, m.outer_pixels, m.s1, m.s2});
        while (m_late.size() > kMaxLateFrames)
            m_late.pop_front();
    } else if (!m.periphery_late && !m.periphery_withheld && !moved_apart) {
        learnBits(m.middle_bytes * 8.0, m.middle_pixels, m.s1, m.outer_bytes * 8.0, m.outer_pixels,
                  m.s2);
    }
    if (m.arrival_ms > 0.0)
        m_last_arrival_ms = m.arrival_ms;
    // The next candidates step from the newest decision; the measured e1 replaces it only when
    // no later decision is already out (a pipelined headset has one in flight).
    if (m_pending.empty())
        m_e1_deg = m.e1_deg;
}

void LiwcPolicy::observeLateArrival(const LateArrival& a) {
    auto it = std::find_if(m_late.begin(), m_late.end(),
                           [&](const LateFrame& f) { return f.index == a.index; });
    if (it == m_late.end())
        return;
    const LateFrame f = *it;
    m_late.erase(it);
    // A new canvas's key frame is a move's cost, not what a frame that holds sends.
    if (a.new_canvas_streams == 0)
        learnBits(a.middle_bytes * 8.0, f.middle_pixels, f.s1, a.outer_bytes * 8.0, f.outer_pixels,
                  f.s2);
}

void LiwcPolicy::learnBits(double middle_bits, double middle_pixels, double s1, double outer_bits,
                           double outer_pixels, double s2) {
    // Bits per pixel as b·s^γ, fitted to the two layers' measured sizes in log space.
    const bool have_mid = middle_pixels > 0 && middle_bits > 0;
    const bool have_out = outer_pixels > 0 && outer_bits > 0;
    const double w = replacesPrior() ? 1.0 : m_config.rate_ema;  // a first one replaces the prior
    if (have_mid && have_out && s2 > 1.05 * s1) {
        const double lm = std::log(middle_bits / middle_pixels);
        const double lo = std::log(outer_bits / outer_pixels);
        const double gamma = std::clamp((lo - lm) / (std::log(s2) - std::log(s1)), 0.0, 2.0);
        const double log_b1 = lm - gamma * std::log(s1);
        m_bits_exponent = (1.0 - w) * m_bits_exponent + w * gamma;
        m_log_bits_at_1 = (1.0 - w) * m_log_bits_at_1 + w * log_b1;
    } else if (have_mid || have_out) {
        const double bits = have_mid ? middle_bits / middle_pixels : outer_bits / outer_pixels;
        const double s = have_mid ? s1 : s2;
        const double log_b1 = std::log(bits) - m_bits_exponent * std::log(std::max(1.0, s));
        m_log_bits_at_1 = (1.0 - w) * m_log_bits_at_1 + w * log_b1;
    }
    // What the law misses of each layer: the layers hold different content, which the one law
    // can only read as γ (a glTF engine in the outer layer around an empty middle: γ at its
    // bound of 2, the outer layer's bits 2.7x under, the link's time ~4x under, and e1 held
    // 4-8° low on a 1.33 Mbit/s link). Its ratio per layer, measured over held frames, puts
    // each layer's own content into what a candidate's bits are predicted from.
    if (m_config.frame_period_objective) {
        const std::array<std::array<double, 3>, 2> layers{
            {{middle_bits, middle_pixels, s1}, {outer_bits, outer_pixels, s2}}};
        for (size_t k = 0; k < layers.size(); ++k) {
            const auto& [bits, pixels, s] = layers[k];
            if (pixels <= 0 || bits <= 0)
                continue;
            const double r = std::log(bits / pixels / bitsPerPixelAt(s));
            m_layer_log_ratio[k] = (1.0 - w) * m_layer_log_ratio[k] + w * r;
        }
    }
    m_bits_law_measured = m_bits_law_measured || have_mid || have_out;
}

double LiwcPolicy::serverMsOf(const FrameMeasurement& m, double sent_ms) const {
    // T_remote runs from when the server could start: the request, or the previous frame's last
    // packet when the request came before it. In that second case the server worked on this
    // frame while the link carried the one before, so the link's time does not add to the
    // server's: when the headset waited (its busy time under T_remote) and so did the link (the
    // frame's transmission under T_remote), the server set the pace and its frame took
    // T_remote. Otherwise T_remote is the server and the transmission in turn.
    const bool overlapped =
        m.request_ms > 0.0 && m_last_arrival_ms > 0.0 && m.request_ms < m_last_arrival_ms;
    if (overlapped && m.t_local_ms < m.t_remote_ms && sent_ms < m.t_remote_ms)
        return m.t_remote_ms;
    return std::max(0.0, m.t_remote_ms - sent_ms);
}

LiwcPolicy::FrameKind LiwcPolicy::learnMoveCost(const FrameMeasurement& m, double predicted_bits) {
    // Whether this frame's e1 differs from the previous observed frame's: its encoders may have
    // opened a new canvas (a key frame, new padding). Its bits over what the bits law (fitted on
    // held frames) predicted, against the same ratio of the next frame that held its e1, is what
    // a move costs the link.
    const bool moved =
        m_last_observed_e1_deg >= 0.0 && std::fabs(m.e1_deg - m_last_observed_e1_deg) > 0.05;
    // The session's first frame opens every encoder (a key frame on each stream): like a move's,
    // its bits are not what a frame that holds costs, so it is kept apart too.
    const bool first = m_last_observed_e1_deg < 0.0;
    m_last_observed_e1_deg = m.e1_deg;
    if (first)
        return FrameKind::kOpening;
    // A frame that held e1 but whose encoder opened a new canvas pays an earlier move's cost
    // late: a canvas shrinks 30 frames after the move that left its layer small, every stream
    // at once (sweep 31337 c13: all four key frames on one held frame; read as the steady
    // state, the predicted T_remote doubled and e1 jumped). Kept apart as a move is; it is
    // not a move, so the moves' frequency does not count it.
    const bool new_canvas = !moved && m.new_canvas_streams > 0;
    if (moved) {
        m_frames_between_moves = (1.0 - kMoveEmaWeight) * m_frames_between_moves +
                                 kMoveEmaWeight * (m_frames_since_move + 1);
        m_frames_since_move = 0;
    } else {
        ++m_frames_since_move;
    }
    const double sent_bits = (m.middle_bytes + m.outer_bytes) * 8.0;
    // A late frame's sizes are what had come by the wait limit, not what it sent.
    if (sent_bits > 0.0 && predicted_bits > 0.0 && !m.periphery_late)
        m_move_bits.add(moved || new_canvas, m.e1_deg, sent_bits / predicted_bits);
    return moved ? FrameKind::kMoved : new_canvas ? FrameKind::kLateCanvas : FrameKind::kHeld;
}

double LiwcPolicy::remoteOffsetMs(uint16_t motion, int bucket) const {
    if (m_config.frame_period_objective && !m_cell_folded[LiwcTable::indexOf(motion, bucket)])
        return m_remote_residual_ms;
    return m_table.offsetMs(motion, bucket);
}

void LiwcPolicy::foldRemoteOffset(uint16_t motion, int bucket, double delta_ms) {
    // The period objective: a cell no frame has folded reads the remote chain's error over every
    // cell (an EMA at the table's α), and its first fold starts there. Read as 0, the error the
    // table had learned vanished whenever the motion code or e1's bucket changed: every
    // candidate's X moved by it at once (-2.5 to 0 ms on a 10 ms X), and e1 flipped 5° and back
    // on consecutive frames (2CylinderEngine, rate:1.33), each move a key frame. Eq. 2's table
    // (the paper simulator) keeps the paper's zero start.
    const size_t cell = LiwcTable::indexOf(motion, bucket);
    const float alpha = m_config.alpha;
    if (m_config.frame_period_objective) {
        if (!m_cell_folded[cell])
            m_table.setOffsetMs(motion, bucket, static_cast<float>(m_remote_residual_ms));
        m_cell_folded[cell] = true;
        m_remote_residual_ms = (1.0 - alpha) * m_remote_residual_ms + alpha * delta_ms;
    }
    m_table.fold(motion, bucket, static_cast<float>(delta_ms), alpha);
}

void LiwcPolicy::learnLocal(const FrameMeasurement& m) {
    const WindowedFit::Vec x{1.0, m.triangles_local * 1e-5, m.pixels_local * 1e-5};
    m_render_apart = m_render_apart || m.t_render_ms > 0.0;
    if (!m_render_apart) {
        m_local_fit.add(x, m.t_local_ms, m.e1_deg);
        return;
    }
    // The fovea render is the busy time's only part that e1 moves: its slope is fitted on the
    // render's own time. Fitted on the whole busy time, whose rest (UCA ~8 ms at the default
    // profile) a host's preemptions shake by several ms a frame, the slope was that noise's
    // over the few degrees e1 had visited, or the prior's: L(15°) 21 ms predicted where the
    // headset was busy 10 ms at any e1 (2CylinderEngine, rate:1.33), and e1 stayed at 5-6°.
    if (m.t_render_ms <= 0.0 || m.t_render_ms > m.t_local_ms)
        return;
    m_local_fit.add(x, m.t_render_ms, m.e1_deg);
    m_local_rest.push_back(m.t_local_ms - m.t_render_ms);
    m_local_rest_sum += m_local_rest.back();
    while (m_local_rest.size() > m_local_fit.window()) {
        m_local_rest_sum -= m_local_rest.front();
        m_local_rest.pop_front();
    }
}

void LiwcPolicy::updateGpuRates(double triangles, double pixels, double t_local_ms) {
    // Recursive least squares with forgetting: x = [1, triangles, pixels]·(1, 1e-5, 1e-5).
    const std::array<double, 3> x{1.0, triangles * 1e-5, pixels * 1e-5};
    const double lambda = m_config.gpu_forgetting;
    auto& P = m_gpu_cov;
    std::array<double, 3> px{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            px[i] += P[i * 3 + j] * x[j];
    double denom = lambda;
    for (int i = 0; i < 3; ++i)
        denom += x[i] * px[i];
    const std::array<double, 3> k{px[0] / denom, px[1] / denom, px[2] / denom};
    const double err =
        t_local_ms - (m_gpu_theta[0] + m_gpu_theta[1] * x[1] + m_gpu_theta[2] * x[2]);
    for (int i = 0; i < 3; ++i)
        m_gpu_theta[i] += k[i] * err;
    // Rates are positive; the fixed cost is not negative.
    m_gpu_theta[0] = std::max(0.0, m_gpu_theta[0]);
    m_gpu_theta[1] = std::max(1e-6, m_gpu_theta[1]);
    m_gpu_theta[2] = std::max(1e-6, m_gpu_theta[2]);
    std::array<double, 9> next{};
    double trace = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            next[i * 3 + j] = (P[i * 3 + j] - k[i] * px[j]) / lambda;
        }
    for (int i = 0; i < 3; ++i)
        trace += next[i * 4];
    // Forgetting inflates the covariance along directions the data never excites; cap it so
    // a sudden new direction cannot produce a wild step.
    if (trace > 100.0)
        for (double& v : next)
            v *= 100.0 / trace;
    P = next;
}

}  // namespace qvr
