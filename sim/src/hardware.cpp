// Timing and power of the modelled headset hardware (paper Table 2, §4.3); constants and their
// sources: docs/MODEL.md.
#include "qvr/sim/hardware.h"

#include <cmath>

#include <fmt/format.h>

#include "qvr/core/config.h"

namespace qvr {

double MobileGpuConfig::samplesPerMs() const {
    // cycles per ms = MHz × 1000.
    return texture_units * samples_per_unit_per_cycle * render.freq_mhz * 1e3;
}

double MobileGpuConfig::passMs(double pixels, double samples_per_px) const {
    if (pixels <= 0.0)
        return 0.0;
    return pass_overhead_ms + pixels * samples_per_px / samplesPerMs();
}

double MobileGpuConfig::dynamicPowerW() const {
    const double f = render.freq_mhz;
    const double v_ratio = voltage(f) / voltage(500.0);
    return dynamic_power_w_at_500 * (f / 500.0) * v_ratio * v_ratio;
}

double MobileGpuConfig::staticPowerW() const {
    return static_power_w_at_500 * voltage(render.freq_mhz) / voltage(500.0);
}

HardwareConfig defaultHardware(double gpu_mhz) {
    HardwareConfig hw;
    hw.gpu.render.freq_mhz = gpu_mhz;
    return hw;
}

Expected<HardwareConfig> parseHardwareConfig(std::string_view toml_text,
                                             std::string_view source_name, double gpu_mhz) {
    auto table = parseTomlText(toml_text, source_name);
    if (!table)
        return makeError(table.error());
    HardwareConfig hw = defaultHardware(gpu_mhz);
    ConfigReader r(*table, std::string(source_name));
    MobileGpuConfig& g = hw.gpu;
    g.render.triangles_per_ms_at_500 =
        r.number("gpu.triangles_per_ms_at_500", g.render.triangles_per_ms_at_500, 1.0, 1e9);
    g.render.pixels_per_ms_at_500 =
        r.number("gpu.pixels_per_ms_at_500", g.render.pixels_per_ms_at_500, 1.0, 1e9);
    g.render.setup_ms = r.number("gpu.setup_ms", g.render.setup_ms, 0.0, 100.0);
    g.texture_units = r.number("gpu.texture_units", g.texture_units, 1.0, 1024.0);
    g.samples_per_unit_per_cycle =
        r.number("gpu.samples_per_unit_per_cycle", g.samples_per_unit_per_cycle, 0.01, 64.0);
    g.pass_overhead_ms = r.number("gpu.pass_overhead_ms", g.pass_overhead_ms, 0.0, 100.0);
    g.preempt_overhead_ms = r.number("gpu.preempt_overhead_ms", g.preempt_overhead_ms, 0.0, 100.0);
    g.atw_samples_per_px = r.number("gpu.atw_samples_per_px", g.atw_samples_per_px, 0.0, 16.0);
    g.comp_samples_per_px = r.number("gpu.comp_samples_per_px", g.comp_samples_per_px, 0.0, 16.0);
    g.static_comp_samples_per_px =
        r.number("gpu.static_comp_samples_per_px", g.static_comp_samples_per_px, 0.0, 16.0);
    g.dynamic_power_w_at_500 =
        r.number("gpu.dynamic_power_w_at_500", g.dynamic_power_w_at_500, 0.0, 100.0);
    g.static_power_w_at_500 =
        r.number("gpu.static_power_w_at_500", g.static_power_w_at_500, 0.0, 100.0);
    g.v0 = r.number("gpu.v0", g.v0, 0.0, 2.0);
    g.v_per_mhz = r.number("gpu.v_per_mhz", g.v_per_mhz, 0.0, 0.01);
    hw.uca.units = r.integer("uca.units", hw.uca.units, 1, 64);
    hw.uca.freq_mhz = r.number("uca.freq_mhz", hw.uca.freq_mhz, 1.0, 10000.0);
    hw.uca.cycles_per_tile = r.number("uca.cycles_per_tile", hw.uca.cycles_per_tile, 1.0, 1e6);
    hw.uca.tile_px = r.integer("uca.tile_px", hw.uca.tile_px, 4, 256);
    hw.uca.power_w = r.number("uca.power_w", hw.uca.power_w, 0.0, 100.0);
    hw.liwc.decision_ms = r.number("liwc.decision_ms", hw.liwc.decision_ms, 0.0, 100.0);
    hw.liwc.power_w = r.number("liwc.power_w", hw.liwc.power_w, 0.0, 100.0);
    hw.remote.server_speedup =
        r.number("remote.server_speedup", hw.remote.server_speedup, 0.01, 1e6);
    hw.remote.encoder_px_per_ms =
        r.number("remote.encoder_px_per_ms", hw.remote.encoder_px_per_ms, 1.0, 1e9);
    hw.remote.decoder_px_per_ms =
        r.number("remote.decoder_px_per_ms", hw.remote.decoder_px_per_ms, 1.0, 1e9);
    hw.remote.decode_overhead_ms =
        r.number("remote.decode_overhead_ms", hw.remote.decode_overhead_ms, 0.0, 100.0);
    hw.cpu.control_logic_ms =
        r.number("cpu.control_logic_ms", hw.cpu.control_logic_ms, 0.0, 1000.0);
    hw.cpu.local_setup_ms = r.number("cpu.local_setup_ms", hw.cpu.local_setup_ms, 0.0, 1000.0);
    hw.cpu.software_control_ms =
        r.number("cpu.software_control_ms", hw.cpu.software_control_ms, 0.0, 1000.0);
    hw.fixed.sensor_ms = r.number("latency.sensor_ms", hw.fixed.sensor_ms, 0.0, 1000.0);
    hw.fixed.display_ms = r.number("latency.display_ms", hw.fixed.display_ms, 0.0, 1000.0);
    const std::string pipeline = r.string("runtime.pipeline", "paper");
    if (pipeline != "paper" && pipeline != "runtime")
        return makeError(std::string(source_name) + ": runtime.pipeline must be \"paper\" or " +
                         "\"runtime\", got \"" + pipeline + "\"");
    hw.runtime_pipeline = pipeline == "runtime";
    RuntimeCosts& rc = hw.runtime;
    auto cost = [&](const char* key, double& v) {
        v = r.number(std::string("runtime.") + key, v, 0.0, 10000.0);
    };
    // A render part's power law and whole-frame scale (PartCost).
    auto powerLaw = [&](const std::string& part, PartCost& pc) {
        pc.power_coef_ms =
            r.number("runtime." + part + "_power_coef_ms", pc.power_coef_ms, 0.0, 10000.0);
        pc.px_exponent = r.number("runtime." + part + "_px_exponent", pc.px_exponent, -4.0, 4.0);
        pc.tri_exponent = r.number("runtime." + part + "_tri_exponent", pc.tri_exponent, -4.0, 4.0);
        pc.full_frame_scale =
            r.number("runtime." + part + "_full_frame_scale", pc.full_frame_scale, 0.01, 100.0);
        pc.ms_per_mfrag =
            r.number("runtime." + part + "_ms_per_mfrag", pc.ms_per_mfrag, 0.0, 10000.0);
        pc.frag_per_px = r.number("runtime." + part + "_frag_per_px", pc.frag_per_px, 0.0, 1000.0);
    };
    cost("decision_base_ms", rc.decision.base_ms);
    cost("decision_ms_per_ktri", rc.decision.ms_per_ktri);
    cost("fovea_base_ms", rc.fovea.base_ms);
    cost("fovea_ms_per_mpx", rc.fovea.ms_per_mpx);
    cost("fovea_ms_per_ktri", rc.fovea.ms_per_ktri);
    powerLaw("fovea", rc.fovea);
    cost("decode_base_ms", rc.decode.base_ms);
    cost("decode_ms_per_mpx", rc.decode.ms_per_mpx);
    cost("uca_base_ms", rc.uca.base_ms);
    cost("uca_ms_per_mpx", rc.uca.ms_per_mpx);
    cost("frame_overhead_ms", rc.frame_overhead_ms);
    cost("scanout_record_ms", rc.scanout_record_ms);
    rc.bits_per_px_at_1 = r.number("runtime.bits_per_px_at_1", rc.bits_per_px_at_1, 0.0, 100.0);
    rc.bits_scale_exponent =
        r.number("runtime.bits_scale_exponent", rc.bits_scale_exponent, -4.0, 4.0);
    rc.bits_outer_per_px_at_1 =
        r.number("runtime.bits_outer_per_px_at_1", rc.bits_outer_per_px_at_1, 0.0, 100.0);
    rc.bits_outer_scale_exponent =
        r.number("runtime.bits_outer_scale_exponent", rc.bits_outer_scale_exponent, -4.0, 4.0);
    rc.bits_full_frame_per_px =
        r.number("runtime.bits_full_frame_per_px", rc.bits_full_frame_per_px, 0.0, 100.0);
    cost("server_render_base_ms", rc.server_render.base_ms);
    cost("server_render_ms_per_mpx", rc.server_render.ms_per_mpx);
    cost("server_render_ms_per_ktri", rc.server_render.ms_per_ktri);
    powerLaw("server_render", rc.server_render);
    cost("encode_base_ms", rc.encode.base_ms);
    cost("encode_ms_per_mpx", rc.encode.ms_per_mpx);
    rc.encode.full_frame_scale =
        r.number("runtime.encode_full_frame_scale", rc.encode.full_frame_scale, 0.01, 100.0);
    cost("server_frame_ms", rc.server_frame_ms);
    cost("link_delay_ms", rc.link_delay_ms);
    rc.packet_payload_bytes =
        r.number("runtime.packet_payload_bytes", rc.packet_payload_bytes, 1.0, 65536.0);
    rc.packet_overhead_bytes =
        r.number("runtime.packet_overhead_bytes", rc.packet_overhead_bytes, 0.0, 65536.0);
    rc.canvas_align_px = r.integer("runtime.canvas_align_px", rc.canvas_align_px, 2, 256);
    if (rc.canvas_align_px % 2 != 0)
        return makeError(std::string(source_name) + ": runtime.canvas_align_px must be even, got " +
                         std::to_string(rc.canvas_align_px));
    rc.canvas_headroom = r.number("runtime.canvas_headroom", rc.canvas_headroom, 0.0, 1.0);
    rc.canvas_shrink_ratio =
        r.number("runtime.canvas_shrink_ratio", rc.canvas_shrink_ratio, 0.0, 1.0);
    rc.canvas_shrink_after_frames =
        r.integer("runtime.canvas_shrink_after_frames", rc.canvas_shrink_after_frames, 1, 100000);
    rc.keyint_frames = r.integer("runtime.keyint_frames", rc.keyint_frames, 0, 100000);
    rc.keyframe_bits_ratio =
        r.number("runtime.keyframe_bits_ratio", rc.keyframe_bits_ratio, 0.0, 1000.0);
    rc.keyframe_outer_bits_ratio =
        r.number("runtime.keyframe_outer_bits_ratio", rc.keyframe_outer_bits_ratio, 0.0, 1000.0);
    rc.keyframe_periodic_bits_ratio = r.number("runtime.keyframe_periodic_bits_ratio",
                                               rc.keyframe_periodic_bits_ratio, 0.0, 1000.0);
    rc.padding_bits_ratio =
        r.number("runtime.padding_bits_ratio", rc.padding_bits_ratio, 0.0, 10.0);
    rc.corun_slowdown = r.number("runtime.corun_slowdown", rc.corun_slowdown, 1.0, 4.0);
    rc.corun_headset_slowdown =
        r.number("runtime.corun_headset_slowdown", rc.corun_headset_slowdown, 1.0, 4.0);
    rc.corun_server_slowdown =
        r.number("runtime.corun_server_slowdown", rc.corun_server_slowdown, 1.0, 4.0);
    rc.speed_reference_headset_ms =
        r.number("runtime.speed_reference_headset_ms", rc.speed_reference_headset_ms, 0.0, 1e5);
    rc.speed_reference_server_ms =
        r.number("runtime.speed_reference_server_ms", rc.speed_reference_server_ms, 0.0, 1e5);
    rc.speed_reference_key = r.string("runtime.speed_reference_key", rc.speed_reference_key);
    constexpr size_t kMaxFrames = 100000;
    rc.bits_frame_key = r.numbers("runtime.bits_frame_key", 0.0, 4294967295.0, kMaxFrames);
    rc.bits_frame_middle = r.numbers("runtime.bits_frame_middle", 0.05, 20.0, kMaxFrames);
    rc.bits_frame_outer = r.numbers("runtime.bits_frame_outer", 0.05, 20.0, kMaxFrames);
    if (auto st = r.finish(); !st)
        return makeError(st.error());
    for (double k : rc.bits_frame_key)
        if (k != std::floor(k))
            return makeError(std::string(source_name) +
                             ": runtime.bits_frame_key must hold integers, got " +
                             fmt::format("{}", k));
    if (rc.bits_frame_middle.size() != rc.bits_frame_key.size() ||
        rc.bits_frame_outer.size() != rc.bits_frame_key.size())
        return makeError(fmt::format(
            "{}: runtime.bits_frame_key, bits_frame_middle and bits_frame_outer must be as long "
            "as one another, got {}, {} and {}",
            source_name, rc.bits_frame_key.size(), rc.bits_frame_middle.size(),
            rc.bits_frame_outer.size()));
    return hw;
}

Expected<HardwareConfig> loadHardwareConfig(const std::string& path, double gpu_mhz) {
    auto text = readTextFile(path);
    if (!text)
        return makeError(text.error());
    return parseHardwareConfig(*text, path, gpu_mhz);
}

}  // namespace qvr

namespace qvr {

std::string runtimeCostsToml(const RuntimeCosts& c) {
    std::string s = "[runtime]\npipeline = \"runtime\"\n";
    auto put = [&](const char* key, double v) { s += fmt::format("{} = {:.6g}\n", key, v); };
    auto putLaw = [&](const std::string& part, const PartCost& pc) {
        put((part + "_power_coef_ms").c_str(), pc.power_coef_ms);
        put((part + "_px_exponent").c_str(), pc.px_exponent);
        put((part + "_tri_exponent").c_str(), pc.tri_exponent);
        put((part + "_full_frame_scale").c_str(), pc.full_frame_scale);
        put((part + "_ms_per_mfrag").c_str(), pc.ms_per_mfrag);
        put((part + "_frag_per_px").c_str(), pc.frag_per_px);
    };
    put("decision_base_ms", c.decision.base_ms);
    put("decision_ms_per_ktri", c.decision.ms_per_ktri);
    put("fovea_base_ms", c.fovea.base_ms);
    put("fovea_ms_per_mpx", c.fovea.ms_per_mpx);
    put("fovea_ms_per_ktri", c.fovea.ms_per_ktri);
    putLaw("fovea", c.fovea);
    put("decode_base_ms", c.decode.base_ms);
    put("decode_ms_per_mpx", c.decode.ms_per_mpx);
    put("uca_base_ms", c.uca.base_ms);
    put("uca_ms_per_mpx", c.uca.ms_per_mpx);
    put("frame_overhead_ms", c.frame_overhead_ms);
    put("scanout_record_ms", c.scanout_record_ms);
    put("bits_per_px_at_1", c.bits_per_px_at_1);
    put("bits_scale_exponent", c.bits_scale_exponent);
    put("bits_outer_per_px_at_1", c.bits_outer_per_px_at_1);
    put("bits_outer_scale_exponent", c.bits_outer_scale_exponent);
    put("bits_full_frame_per_px", c.bits_full_frame_per_px);
    put("server_render_base_ms", c.server_render.base_ms);
    put("server_render_ms_per_mpx", c.server_render.ms_per_mpx);
    put("server_render_ms_per_ktri", c.server_render.ms_per_ktri);
    putLaw("server_render", c.server_render);
    put("encode_base_ms", c.encode.base_ms);
    put("encode_ms_per_mpx", c.encode.ms_per_mpx);
    put("encode_full_frame_scale", c.encode.full_frame_scale);
    put("server_frame_ms", c.server_frame_ms);
    put("link_delay_ms", c.link_delay_ms);
    put("packet_payload_bytes", c.packet_payload_bytes);
    put("packet_overhead_bytes", c.packet_overhead_bytes);
    s += fmt::format("canvas_align_px = {}\n", c.canvas_align_px);
    put("canvas_headroom", c.canvas_headroom);
    put("canvas_shrink_ratio", c.canvas_shrink_ratio);
    s += fmt::format("canvas_shrink_after_frames = {}\n", c.canvas_shrink_after_frames);
    s += fmt::format("keyint_frames = {}\n", c.keyint_frames);
    put("keyframe_bits_ratio", c.keyframe_bits_ratio);
    put("keyframe_outer_bits_ratio", c.keyframe_outer_bits_ratio);
    put("keyframe_periodic_bits_ratio", c.keyframe_periodic_bits_ratio);
    put("padding_bits_ratio", c.padding_bits_ratio);
    put("corun_slowdown", c.corun_slowdown);
    if (c.corun_headset_slowdown > 0.0)  // 0: not measured, corun_slowdown stands
        put("corun_headset_slowdown", c.corun_headset_slowdown);
    if (c.corun_server_slowdown > 0.0)
        put("corun_server_slowdown", c.corun_server_slowdown);
    if (!c.bits_frame_key.empty()) {
        auto putArray = [&](const char* key, const std::vector<double>& v, const char* f) {
            s += fmt::format("{} = [", key);
            for (size_t i = 0; i < v.size(); ++i)
                s += fmt::format(fmt::runtime(i ? std::string(", ") + f : std::string(f)), v[i]);
            s += "]\n";
        };
        putArray("bits_frame_key", c.bits_frame_key, "{:.0f}");
        putArray("bits_frame_middle", c.bits_frame_middle, "{:.4f}");
        putArray("bits_frame_outer", c.bits_frame_outer, "{:.4f}");
    }
    if (c.speed_reference_headset_ms > 0.0 && c.speed_reference_server_ms > 0.0) {
        put("speed_reference_headset_ms", c.speed_reference_headset_ms);
        put("speed_reference_server_ms", c.speed_reference_server_ms);
        s += fmt::format("speed_reference_key = \"{}\"\n", c.speed_reference_key);
    }
    return s;
}

}  // namespace qvr
