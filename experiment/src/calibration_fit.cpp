// The fit of a calibration's samples to RuntimeCosts (calibration_fit.h).
#include "qvr/experiment/calibration_fit.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "qvr/net/link_emulator.h"
#include "qvr/net/protocol.h"

namespace qvr::experiment {

double upperMedian(std::vector<double> v) {
    if (v.empty())
        return 0.0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

double meanOf(const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v)
        sum += x;
    return v.empty() ? 0.0 : sum / double(v.size());
}

CalibratedPart summarisePart(const std::string& name, const std::string& what,
                             const std::vector<CostSample>& samples, const PartCost& cost) {
    CalibratedPart p;
    p.name = name;
    p.what = what;
    p.samples = static_cast<int>(samples.size());
    p.cost = cost;
    if (samples.empty())
        return p;
    std::vector<double> ms;
    for (const CostSample& x : samples)
        ms.push_back(x.ms);
    std::sort(ms.begin(), ms.end());
    p.median_ms = ms[ms.size() / 2];
    p.min_ms = ms.front();
    p.max_ms = ms.back();
    p.residual_rms_pct = costResidualRmsPct(samples, cost);
    for (const CostSample& x : samples) {
        p.samples_ms_px_tri.push_back({x.ms, x.pixels, x.triangles});
        p.samples_fragments.push_back(x.fragments);
        p.samples_full_frame.push_back(x.full_frame ? 1 : 0);
    }
    return p;
}

double fitPaddingBitsRatio(const std::vector<PaddingSample>& samples) {
    double sxy = 0.0, sxx = 0.0;
    for (const PaddingSample& ps : samples) {
        sxy += ps.extra * (ps.ratio - 1.0);
        sxx += ps.extra * ps.extra;
    }
    return sxx > 0.0 ? std::clamp(sxy / sxx, 0.0, 10.0) : 0.0;
}

void fitBitsByFrame(const std::array<std::vector<BitsSample>, 2>& bits,
                    const std::vector<double>& frame_content_key, RuntimeCosts& costs) {
    const size_t frames = frame_content_key.size();
    std::array<std::vector<double>, 2> spent, law_bits;
    for (size_t li = 0; li < 2; ++li) {
        spent[li].assign(frames, 0.0);
        law_bits[li].assign(frames, 0.0);
        for (const BitsSample& b : bits[li]) {
            if (b.frame < 0 || size_t(b.frame) >= frames)
                continue;
            spent[li][size_t(b.frame)] += b.bits;
            law_bits[li][size_t(b.frame)] += b.pixels * costs.bitsPerPx(b.scale, li == 1);
        }
    }
    costs.bits_frame_key.assign(frames, 0.0);
    costs.bits_frame_middle.assign(frames, 1.0);
    costs.bits_frame_outer.assign(frames, 1.0);
    for (size_t i = 0; i < frames; ++i) {
        if (!(law_bits[0][i] > 0.0) || !(law_bits[1][i] > 0.0) || !(spent[0][i] > 0.0) ||
            !(spent[1][i] > 0.0))
            continue;  // the warm-up's frames, a key frame: the law alone
        costs.bits_frame_key[i] = frame_content_key[i];
        costs.bits_frame_middle[i] = std::clamp(spent[0][i] / law_bits[0][i], 0.05, 20.0);
        costs.bits_frame_outer[i] = std::clamp(spent[1][i] / law_bits[1][i], 0.05, 20.0);
    }
    // The hardware file holds only the frames measured.
    while (!costs.bits_frame_key.empty() && costs.bits_frame_key.back() == 0.0) {
        costs.bits_frame_key.pop_back();
        costs.bits_frame_middle.pop_back();
        costs.bits_frame_outer.pop_back();
    }
}

namespace {

// Bits per pixel: b·s^γ for the middle and the outer layer apart, γ from the logs, b from the
// mean (sim/cost_fit.h fitBitsLaw).
void fitBitsLaws(const std::array<std::vector<BitsSample>, 2>& bits, Calibration& cal) {
    for (size_t li = 0; li < 2; ++li) {
        const BitsLaw law = fitBitsLaw(bits[li]);
        if (law.bits_per_px_at_1 <= 0.0)
            continue;
        (li == 0 ? cal.costs.bits_per_px_at_1 : cal.costs.bits_outer_per_px_at_1) =
            law.bits_per_px_at_1;
        (li == 0 ? cal.costs.bits_scale_exponent : cal.costs.bits_outer_scale_exponent) =
            law.scale_exponent;
        cal.bits_mean_over_geometric[li] = law.bits_per_px_at_1 / law.geometric_b;
        cal.bits_samples += static_cast<int>(bits[li].size());
    }
}

// The codec's bits: the layers' laws frame by frame, key frames, padding and the whole frame's.
void fitCodec(const CalibrationSamples& s, Calibration& cal) {
    cal.costs.padding_bits_ratio = fitPaddingBitsRatio(s.padding);
    cal.padding_samples = static_cast<int>(s.padding.size());
    fitBitsLaws(s.bits, cal);
    fitBitsByFrame(s.bits, s.frame_content_key, cal.costs);
    cal.costs.keyframe_bits_ratio = upperMedian(s.keyframe_ratio[0]);
    cal.costs.keyframe_outer_bits_ratio = upperMedian(s.keyframe_ratio[1]);
    cal.costs.keyframe_periodic_bits_ratio = upperMedian(s.periodic_keyframe_ratio);
    // The mean, as for the layers' law: the model's bytes per frame are a mean.
    cal.costs.bits_full_frame_per_px = meanOf(s.full_frame_bits_per_px);
    cal.bits_full_frame_samples = static_cast<int>(s.full_frame_bits_per_px.size());
}

}  // namespace

void fitCalibration(const CalibrationSamples& s, Calibration& cal) {
    // The decision is one pass over the clusters whatever e1 is: a constant.
    cal.costs.decision = fitPartCost(s.decision, {.use_px = false, .use_tri = false});
    cal.costs.frame_overhead_ms = upperMedian(s.plan_ms);
    cal.costs.scanout_record_ms = upperMedian(s.video_copy_ms);
    fitCodec(s, cal);
    // The render passes may follow the power law (llvmpipe's fovea pass is not linear over
    // 3 kpx … 4 Mpx); the whole frame gets its own scale.
    const CostFitOptions render_fit{.use_px = true, .use_tri = true, .allow_power = true};
    const CostFitOptions px_only{.use_px = true, .use_tri = false, .allow_power = false};
    // A render pass charges its shaded fragments (its overdraw) and triangles, not its pixels:
    // two poses with the same pixels and triangles can cost 2× apart. The server's layers too:
    // fitted on pixels, a run on another motion than the calibration's took 1.26× the law.
    CostFitOptions fragment_fit = render_fit;
    fragment_fit.use_frag = true;
    cal.costs.fovea = fitPartCost(s.fovea, fragment_fit);
    cal.costs.server_render = fitPartCost(s.server_render, fragment_fit);
    cal.costs.encode = fitPartCost(s.encode, px_only);
    cal.costs.decode = fitPartCost(s.decode, px_only);
    cal.costs.uca = fitPartCost(s.uca, px_only);
    cal.parts.push_back(summarisePart("decision", "cluster ring counts, both eyes", s.decision,
                                      cal.costs.decision));
    cal.parts.push_back(summarisePart("fovea/local", "one eye's fovea or full-frame pass", s.fovea,
                                      cal.costs.fovea));
    cal.parts.push_back(summarisePart("server render",
                                      "one periphery or whole-frame layer (ktri drawn: LOD, holes)",
                                      s.server_render, cal.costs.server_render));
    cal.parts.push_back(
        summarisePart("encode", "one layer or whole frame, P-frame, running stream (canvas px)",
                      s.encode, cal.costs.encode));
    cal.parts.push_back(summarisePart("decode",
                                      "one stream, P-frame, in a headset frame (canvas px)",
                                      s.decode, cal.costs.decode));
    cal.parts.push_back(
        summarisePart("uca", "one frame, both eyes, per layer pixel read", s.uca, cal.costs.uca));
}

Calibration::CoRun fitCoRun(const CoRunPairs& pairs, const std::string& side, int load_core,
                            const std::string& load_side) {
    std::vector<double> ratios, alone = pairs.alone_ms, shared = pairs.shared_ms;
    for (size_t j = 0; j < pairs.alone_ms.size() && j < pairs.shared_ms.size(); ++j)
        ratios.push_back(pairs.shared_ms[j] / std::max(1e-6, pairs.alone_ms[j]));
    Calibration::CoRun out;
    if (ratios.empty())
        return out;
    // The slowdown comes and goes with what the host does: many pairs, their geometric mean.
    double log_sum = 0.0;
    for (double x : ratios)
        log_sum += std::log(x);
    const double geo_mean = std::exp(log_sum / double(ratios.size()));
    std::sort(ratios.begin(), ratios.end());
    std::sort(alone.begin(), alone.end());
    std::sort(shared.begin(), shared.end());
    out.alone_ms = alone[alone.size() / 2];
    out.shared_ms = shared[shared.size() / 2];
    out.samples = static_cast<int>(ratios.size());
    out.ratio_p10 = ratios[ratios.size() / 10];
    out.ratio_p90 = ratios[ratios.size() * 9 / 10];
    out.slowdown = std::clamp(geo_mean, 1.0, 4.0);
    out.note = fmt::format(
        "{} frames (e1 = {:g} deg) {:.2f} ms alone, {:.2f} ms with core {} doing the "
        "{}'s (medians); slowdown x{:.3f} (geometric mean of {} paired frames, p10-p90 "
        "{:.2f}-{:.2f})",
        side, kCoRunE1Deg, out.alone_ms, out.shared_ms, load_core, load_side, out.slowdown,
        ratios.size(), out.ratio_p10, out.ratio_p90);
    return out;
}

void describeLinks(Calibration& cal) {
    cal.costs.packet_payload_bytes = double(net::kMediaChunkBytes);
    cal.costs.packet_overhead_bytes = double(net::kMediaHeaderBytes);
    cal.links = nlohmann::json::object();
    for (const std::string& name : qvr::linkProfileNames()) {
        auto lc = qvr::parseLinkSpec(name);
        if (lc)
            cal.links[name] = {{"rate_bps", lc->rate_bps}, {"delay_ms", lc->delay_ms}};
    }
}

}  // namespace qvr::experiment
