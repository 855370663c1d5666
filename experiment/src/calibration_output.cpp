// A calibration's outputs: the hardware file (TOML, sim/hardware.h's grammar with the
// measurement's summary in comments), its JSON copy with every sample, and the one-line texts
// both and the command line print.
#include "qvr/experiment/calibration.h"

#include <algorithm>
#include <array>

#include <fmt/format.h>

namespace qvr::experiment {

std::string costLawText(const PartCost& c) {
    std::string s = c.power_coef_ms > 0.0
                        ? fmt::format("{:.4g}·Mpx^{:.3f}·ktri^{:.3f}", c.power_coef_ms,
                                      c.px_exponent, c.tri_exponent)
                        : fmt::format("{:.3f} + {:.3f}·Mpx + {:.4f}·ktri", c.base_ms, c.ms_per_mpx,
                                      c.ms_per_ktri);
    if (c.power_coef_ms <= 0.0 && c.ms_per_mfrag > 0.0)
        s += fmt::format(" + {:.3f}·Mfrag ({:.2f} fragments a pixel)", c.ms_per_mfrag,
                         c.frag_per_px);
    if (c.full_frame_scale != 1.0)
        s += fmt::format("; whole frame {:.3f}×", c.full_frame_scale);
    return s;
}

namespace {
nlohmann::json corunJson(const Calibration::CoRun& c) {
    return {{"slowdown", c.slowdown},
            {"frame_alone_ms", c.alone_ms},
            {"frame_shared_ms", c.shared_ms},
            {"paired_frames", c.samples},
            {"ratio_p10", c.ratio_p10},
            {"ratio_p90", c.ratio_p90},
            {"note", c.note}};
}
}  // namespace

nlohmann::json Calibration::toJson() const {
    nlohmann::json parts_json = nlohmann::json::array();
    for (const CalibratedPart& p : parts)
        parts_json.push_back({{"name", p.name},
                              {"sample", p.what},
                              {"samples", p.samples},
                              {"base_ms", p.cost.base_ms},
                              {"ms_per_mpx", p.cost.ms_per_mpx},
                              {"ms_per_ktri", p.cost.ms_per_ktri},
                              {"law", p.cost.power_coef_ms > 0.0 ? "power" : "linear"},
                              {"power_coef_ms", p.cost.power_coef_ms},
                              {"px_exponent", p.cost.px_exponent},
                              {"tri_exponent", p.cost.tri_exponent},
                              {"ms_per_mfrag", p.cost.ms_per_mfrag},
                              {"frag_per_px", p.cost.frag_per_px},
                              {"full_frame_scale", p.cost.full_frame_scale},
                              {"median_ms", p.median_ms},
                              {"min_ms", p.min_ms},
                              {"max_ms", p.max_ms},
                              {"residual_rms_pct", p.residual_rms_pct},
                              {"samples_ms_px_tri", p.samples_ms_px_tri},
                              {"samples_fragments", p.samples_fragments},
                              {"samples_full_frame", p.samples_full_frame}});
    return {{"machine", machine},
            {"date", date},
            {"command", command},
            {"seconds", seconds},
            {"load_avg_before", load_avg_before},
            {"parts", parts_json},
            {"links", links},
            {"frame_overhead_ms", costs.frame_overhead_ms},
            {"scanout_record_ms", costs.scanout_record_ms},
            {"bits_per_px_at_1", costs.bits_per_px_at_1},
            {"bits_scale_exponent", costs.bits_scale_exponent},
            {"bits_outer_per_px_at_1", costs.bits_outer_per_px_at_1},
            {"bits_outer_scale_exponent", costs.bits_outer_scale_exponent},
            {"bits_samples", bits_samples},
            {"bits_mean_over_geometric", bits_mean_over_geometric},
            {"bits_full_frame_per_px", costs.bits_full_frame_per_px},
            {"bits_full_frame_samples", bits_full_frame_samples},
            {"bits_frame",
             {{"content_key", costs.bits_frame_key},
              {"middle_over_law", costs.bits_frame_middle},
              {"outer_over_law", costs.bits_frame_outer}}},
            {"keyframe_bits_ratio", costs.keyframe_bits_ratio},
            {"keyframe_outer_bits_ratio", costs.keyframe_outer_bits_ratio},
            {"padding_bits_ratio", costs.padding_bits_ratio},
            {"keyframe_periodic_bits_ratio", costs.keyframe_periodic_bits_ratio},
            {"padding_samples", padding_samples},
            {"codec_by_e1", codec_by_e1},
            {"packet_payload_bytes", costs.packet_payload_bytes},
            {"packet_overhead_bytes", costs.packet_overhead_bytes},
            {"corun_headset", corunJson(corun_headset)},
            {"corun_server", corunJson(corun_server)},
            {"speed_reference",
             {{"headset_frame_ms", costs.speed_reference_headset_ms},
              {"server_frame_ms", costs.speed_reference_server_ms},
              {"key", costs.speed_reference_key},
              {"note", speed_note},
              {"probes", [this] {
                   nlohmann::json a = nlohmann::json::array();
                   for (const SpeedSample& p : speed_probes)
                       a.push_back(
                           {{"headset_frame_ms", p.headset_ms}, {"server_frame_ms", p.server_ms}});
                   return a;
               }()}}}};
}

// The frame-by-frame bits in a line: how many frames, and the middle's and outer's mean over
// the law in the motion's first second (frames up to 30) and after it, with their range.
std::string bitsByFrameText(const RuntimeCosts& c) {
    std::array<std::array<double, 3>, 4> acc{};  // {sum, min, max} middle/outer × early/late
    std::array<int, 2> n{};
    for (auto& a : acc)
        a = {0.0, 1e9, 0.0};
    for (size_t k = 0; k < c.bits_frame_key.size(); ++k) {
        if (c.bits_frame_key[k] == 0.0)
            continue;
        const size_t late = k < 30 ? 0 : 1;
        ++n[late];
        for (size_t li = 0; li < 2; ++li) {
            const double f = li == 0 ? c.bits_frame_middle[k] : c.bits_frame_outer[k];
            auto& a = acc[li * 2 + late];
            a[0] += f;
            a[1] = std::min(a[1], f);
            a[2] = std::max(a[2], f);
        }
    }
    if (n[0] + n[1] == 0)
        return "none (the law alone)";
    auto part = [&](size_t late, const char* what) {
        if (n[late] == 0)
            return std::string();
        return fmt::format(
            "{} {} frames: middle {:.3f}x [{:.2f}, {:.2f}], outer {:.3f}x "
            "[{:.2f}, {:.2f}]",
            what, n[late], acc[late][0] / n[late], acc[late][1], acc[late][2],
            acc[2 + late][0] / n[late], acc[2 + late][1], acc[2 + late][2]);
    };
    std::string early = part(0, "frames < 30,"), later = part(1, "frames >= 30,");
    return early + (early.empty() || later.empty() ? "" : "; ") + later + " of the law";
}

std::string Calibration::toToml() const {
    std::string s = fmt::format(
        "# qvr calibrate: this machine's runtime costs (docs/MODEL.md §9).\n# {}\n# {}, {:.0f} s, "
        "load average {:.2f} before\n",
        command, date, seconds, load_avg_before);
    s += "# machine: " + machine + "\n";
    for (const CalibratedPart& p : parts)
        s += fmt::format(
            "# {:14} {:3} samples ({}): median {:.2f} ms [{:.2f}, {:.2f}], {} ms, fit "
            "residual {:.0f}% RMS\n",
            p.name, p.samples, p.what, p.median_ms, p.min_ms, p.max_ms, costLawText(p.cost),
            p.residual_rms_pct);
    s += fmt::format(
        "# bits per layer pixel: middle {:.4f}·s^{:.3f}, outer {:.4f}·s^{:.3f}, over {} P-frames "
        "(the mean; {:.3f}x / {:.3f}x the geometric mean)\n",
        costs.bits_per_px_at_1, costs.bits_scale_exponent, costs.bits_outer_per_px_at_1,
        costs.bits_outer_scale_exponent, bits_samples, bits_mean_over_geometric[0],
        bits_mean_over_geometric[1]);
    s += fmt::format("# bits per whole-frame pixel (remote's layer): {:.4f}, over {} P-frames\n",
                     costs.bits_full_frame_per_px, bits_full_frame_samples);
    s += "# bits frame by frame on the calibration's motion: " + bitsByFrameText(costs) + "\n";
    s += fmt::format(
        "# key frame of a new encoder: {:.2f}x a P-frame's bits (middle), {:.2f}x (outer); "
        "periodic: {:.2f}x; padding beyond the snug canvas: {:.3f} of a layer pixel's bits per "
        "pixel, over {} P-frame pairs\n",
        costs.keyframe_bits_ratio, costs.keyframe_outer_bits_ratio,
        costs.keyframe_periodic_bits_ratio, costs.padding_bits_ratio, padding_samples);
    s += "# co-running, headset: " + corun_headset.note + "\n";
    s += "# co-running, server: " + corun_server.note + "\n";
    if (!speed_probes.empty())
        s += fmt::format(
            "# speed reference (the probe's headset/server frame, the mean of {}): {}\n",
            speed_probes.size(), speedProbesText(speed_probes));
    if (!speed_note.empty())
        s += "# " + speed_note + "\n";
    return s + runtimeCostsToml(costs);
}

std::string calibrationSummaryText(const Calibration& cal) {
    const RuntimeCosts& c = cal.costs;
    std::string s = fmt::format("  {:14} {:>7} {:>9} {:>9} {:>9} {:>8}  {}\n", "part", "samples",
                                "median", "min", "max", "fit RMS", "law (ms)");
    for (const CalibratedPart& p : cal.parts)
        s += fmt::format("  {:14} {:>7} {:>9.2f} {:>9.2f} {:>9.2f} {:>7.0f}%  {}\n", p.name,
                         p.samples, p.median_ms, p.min_ms, p.max_ms, p.residual_rms_pct,
                         costLawText(p.cost));
    s += fmt::format(
        "  frame overhead (plan) {:.3f} ms; display video copy {:.3f} ms; packets {} + {} bytes; "
        "took {:.0f} s, load average {:.2f} before\n",
        c.frame_overhead_ms, c.scanout_record_ms, c.packet_payload_bytes, c.packet_overhead_bytes,
        cal.seconds, cal.load_avg_before);
    s += fmt::format(
        "  codec: P-frame bits per layer pixel middle {:.4f}·s^{:.3f}, outer {:.4f}·s^{:.3f} (the "
        "mean: {:.3f}x / {:.3f}x the geometric mean); key frame {:.2f}x / {:.2f}x a P-frame (new "
        "encoder), {:.2f}x (periodic); padding {:.3f} of a layer pixel's bits ({} pairs)\n",
        c.bits_per_px_at_1, c.bits_scale_exponent, c.bits_outer_per_px_at_1,
        c.bits_outer_scale_exponent, cal.bits_mean_over_geometric[0],
        cal.bits_mean_over_geometric[1], c.keyframe_bits_ratio, c.keyframe_outer_bits_ratio,
        c.keyframe_periodic_bits_ratio, c.padding_bits_ratio, cal.padding_samples);
    s += fmt::format("  codec: P-frame bits per whole-frame pixel (remote) {:.4f} ({} P-frames)\n",
                     c.bits_full_frame_per_px, cal.bits_full_frame_samples);
    s += fmt::format("  codec: bits frame by frame on the calibration's motion: {}\n",
                     bitsByFrameText(c));
    s += fmt::format("  co-running, headset: {}\n", cal.corun_headset.note);
    s += fmt::format("  co-running, server: {}\n", cal.corun_server.note);
    s += fmt::format("  speed reference: {}\n",
                     cal.speed_note.empty()
                         ? fmt::format("headset frame {:.2f} ms, server frame {:.2f} ms, the "
                                       "mean of {}",
                                       c.speed_reference_headset_ms, c.speed_reference_server_ms,
                                       speedProbesText(cal.speed_probes))
                         : cal.speed_note);
    return s;
}

}  // namespace qvr::experiment
