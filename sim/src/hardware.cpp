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

namespace {

using Field = HardwareField;
using Written = HardwareField::Written;

// Where a key lives in HardwareConfig.
#define QVR_HW_AT(member) [](HardwareConfig& h) -> HardwareField::Ref { return &h.member; }

// A number; calibrated costs keep six significant digits in the file.
Field num(std::string_view path, double lo, double hi, HardwareField::Ref (*at)(HardwareConfig&),
          std::string_view format = "{}", Written written = Written::kAlways) {
    return {path, lo, hi, at, format, written};
}
Field cost(std::string_view path, double lo, double hi, HardwareField::Ref (*at)(HardwareConfig&),
           Written written = Written::kAlways) {
    return {path, lo, hi, at, "{:.6g}", written};
}
Field integer(std::string_view path, int lo, int hi, HardwareField::Ref (*at)(HardwareConfig&),
              HardwareField::Check check = HardwareField::Check::kNone) {
    Field f{path, double(lo), double(hi), at, "{}", Written::kAlways};
    f.check = check;
    return f;
}

// A render part's power law, whole-frame scale and fragments (PartCost), under `part`.
#define QVR_HW_POWER_LAW(part, member)                                                             \
    cost("runtime." part "_power_coef_ms", 0.0, 10000.0, QVR_HW_AT(runtime.member.power_coef_ms)), \
        cost("runtime." part "_px_exponent", -4.0, 4.0, QVR_HW_AT(runtime.member.px_exponent)),    \
        cost("runtime." part "_tri_exponent", -4.0, 4.0, QVR_HW_AT(runtime.member.tri_exponent)),  \
        cost("runtime." part "_full_frame_scale", 0.01, 100.0,                                     \
             QVR_HW_AT(runtime.member.full_frame_scale)),                                          \
        cost("runtime." part "_ms_per_mfrag", 0.0, 10000.0,                                        \
             QVR_HW_AT(runtime.member.ms_per_mfrag)),                                              \
        cost("runtime." part "_frag_per_px", 0.0, 1000.0, QVR_HW_AT(runtime.member.frag_per_px))

std::vector<HardwareField> makeHardwareFields() {
    constexpr double kMs = 10000.0;  // every runtime cost in ms
    constexpr double kMaxFrames = 100000.0;
    std::vector<Field> f = {
        num("gpu.triangles_per_ms_at_500", 1.0, 1e9, QVR_HW_AT(gpu.render.triangles_per_ms_at_500)),
        num("gpu.pixels_per_ms_at_500", 1.0, 1e9, QVR_HW_AT(gpu.render.pixels_per_ms_at_500)),
        num("gpu.setup_ms", 0.0, 100.0, QVR_HW_AT(gpu.render.setup_ms)),
        num("gpu.texture_units", 1.0, 1024.0, QVR_HW_AT(gpu.texture_units)),
        num("gpu.samples_per_unit_per_cycle", 0.01, 64.0,
            QVR_HW_AT(gpu.samples_per_unit_per_cycle)),
        num("gpu.pass_overhead_ms", 0.0, 100.0, QVR_HW_AT(gpu.pass_overhead_ms)),
        num("gpu.preempt_overhead_ms", 0.0, 100.0, QVR_HW_AT(gpu.preempt_overhead_ms)),
        num("gpu.atw_samples_per_px", 0.0, 16.0, QVR_HW_AT(gpu.atw_samples_per_px)),
        num("gpu.comp_samples_per_px", 0.0, 16.0, QVR_HW_AT(gpu.comp_samples_per_px)),
        num("gpu.static_comp_samples_per_px", 0.0, 16.0, QVR_HW_AT(gpu.static_comp_samples_per_px)),
        num("gpu.dynamic_power_w_at_500", 0.0, 100.0, QVR_HW_AT(gpu.dynamic_power_w_at_500)),
        num("gpu.static_power_w_at_500", 0.0, 100.0, QVR_HW_AT(gpu.static_power_w_at_500)),
        num("gpu.v0", 0.0, 2.0, QVR_HW_AT(gpu.v0)),
        num("gpu.v_per_mhz", 0.0, 0.01, QVR_HW_AT(gpu.v_per_mhz)),
        integer("uca.units", 1, 64, QVR_HW_AT(uca.units)),
        num("uca.freq_mhz", 1.0, 10000.0, QVR_HW_AT(uca.freq_mhz)),
        num("uca.cycles_per_tile", 1.0, 1e6, QVR_HW_AT(uca.cycles_per_tile)),
        integer("uca.tile_px", 4, 256, QVR_HW_AT(uca.tile_px)),
        num("uca.power_w", 0.0, 100.0, QVR_HW_AT(uca.power_w)),
        num("liwc.decision_ms", 0.0, 100.0, QVR_HW_AT(liwc.decision_ms)),
        num("liwc.power_w", 0.0, 100.0, QVR_HW_AT(liwc.power_w)),
        num("remote.server_speedup", 0.01, 1e6, QVR_HW_AT(remote.server_speedup)),
        num("remote.encoder_px_per_ms", 1.0, 1e9, QVR_HW_AT(remote.encoder_px_per_ms)),
        num("remote.decoder_px_per_ms", 1.0, 1e9, QVR_HW_AT(remote.decoder_px_per_ms)),
        num("remote.decode_overhead_ms", 0.0, 100.0, QVR_HW_AT(remote.decode_overhead_ms)),
        num("cpu.control_logic_ms", 0.0, 1000.0, QVR_HW_AT(cpu.control_logic_ms)),
        num("cpu.local_setup_ms", 0.0, 1000.0, QVR_HW_AT(cpu.local_setup_ms)),
        num("cpu.software_control_ms", 0.0, 1000.0, QVR_HW_AT(cpu.software_control_ms)),
        num("latency.sensor_ms", 0.0, 1000.0, QVR_HW_AT(fixed.sensor_ms)),
        num("latency.display_ms", 0.0, 1000.0, QVR_HW_AT(fixed.display_ms)),
        {"runtime.pipeline", 0.0, 0.0, QVR_HW_AT(runtime_pipeline), "\"{}\""},
        cost("runtime.decision_base_ms", 0.0, kMs, QVR_HW_AT(runtime.decision.base_ms)),
        cost("runtime.decision_ms_per_ktri", 0.0, kMs, QVR_HW_AT(runtime.decision.ms_per_ktri)),
        cost("runtime.fovea_base_ms", 0.0, kMs, QVR_HW_AT(runtime.fovea.base_ms)),
        cost("runtime.fovea_ms_per_mpx", 0.0, kMs, QVR_HW_AT(runtime.fovea.ms_per_mpx)),
        cost("runtime.fovea_ms_per_ktri", 0.0, kMs, QVR_HW_AT(runtime.fovea.ms_per_ktri)),
        QVR_HW_POWER_LAW("fovea", fovea),
        cost("runtime.decode_base_ms", 0.0, kMs, QVR_HW_AT(runtime.decode.base_ms)),
        cost("runtime.decode_ms_per_mpx", 0.0, kMs, QVR_HW_AT(runtime.decode.ms_per_mpx)),
        cost("runtime.uca_base_ms", 0.0, kMs, QVR_HW_AT(runtime.uca.base_ms)),
        cost("runtime.uca_ms_per_mpx", 0.0, kMs, QVR_HW_AT(runtime.uca.ms_per_mpx)),
        cost("runtime.frame_overhead_ms", 0.0, kMs, QVR_HW_AT(runtime.frame_overhead_ms)),
        cost("runtime.scanout_record_ms", 0.0, kMs, QVR_HW_AT(runtime.scanout_record_ms)),
        cost("runtime.bits_per_px_at_1", 0.0, 100.0, QVR_HW_AT(runtime.bits_per_px_at_1)),
        cost("runtime.bits_scale_exponent", -4.0, 4.0, QVR_HW_AT(runtime.bits_scale_exponent)),
        cost("runtime.bits_outer_per_px_at_1", 0.0, 100.0,
             QVR_HW_AT(runtime.bits_outer_per_px_at_1)),
        cost("runtime.bits_outer_scale_exponent", -4.0, 4.0,
             QVR_HW_AT(runtime.bits_outer_scale_exponent)),
        cost("runtime.bits_full_frame_per_px", 0.0, 100.0,
             QVR_HW_AT(runtime.bits_full_frame_per_px)),
        cost("runtime.server_render_base_ms", 0.0, kMs, QVR_HW_AT(runtime.server_render.base_ms)),
        cost("runtime.server_render_ms_per_mpx", 0.0, kMs,
             QVR_HW_AT(runtime.server_render.ms_per_mpx)),
        cost("runtime.server_render_ms_per_ktri", 0.0, kMs,
             QVR_HW_AT(runtime.server_render.ms_per_ktri)),
        QVR_HW_POWER_LAW("server_render", server_render),
        cost("runtime.encode_base_ms", 0.0, kMs, QVR_HW_AT(runtime.encode.base_ms)),
        cost("runtime.encode_ms_per_mpx", 0.0, kMs, QVR_HW_AT(runtime.encode.ms_per_mpx)),
        cost("runtime.encode_full_frame_scale", 0.01, 100.0,
             QVR_HW_AT(runtime.encode.full_frame_scale)),
        cost("runtime.server_frame_ms", 0.0, kMs, QVR_HW_AT(runtime.server_frame_ms)),
        cost("runtime.link_delay_ms", 0.0, kMs, QVR_HW_AT(runtime.link_delay_ms)),
        cost("runtime.packet_payload_bytes", 1.0, 65536.0, QVR_HW_AT(runtime.packet_payload_bytes)),
        cost("runtime.packet_overhead_bytes", 0.0, 65536.0,
             QVR_HW_AT(runtime.packet_overhead_bytes)),
        integer("runtime.canvas_align_px", 2, 256, QVR_HW_AT(runtime.canvas_align_px),
                HardwareField::Check::kEven),
        cost("runtime.canvas_headroom", 0.0, 1.0, QVR_HW_AT(runtime.canvas_headroom)),
        cost("runtime.canvas_shrink_ratio", 0.0, 1.0, QVR_HW_AT(runtime.canvas_shrink_ratio)),
        integer("runtime.canvas_shrink_after_frames", 1, 100000,
                QVR_HW_AT(runtime.canvas_shrink_after_frames)),
        integer("runtime.keyint_frames", 0, 100000, QVR_HW_AT(runtime.keyint_frames)),
        cost("runtime.keyframe_bits_ratio", 0.0, 1000.0, QVR_HW_AT(runtime.keyframe_bits_ratio)),
        cost("runtime.keyframe_outer_bits_ratio", 0.0, 1000.0,
             QVR_HW_AT(runtime.keyframe_outer_bits_ratio)),
        cost("runtime.keyframe_periodic_bits_ratio", 0.0, 1000.0,
             QVR_HW_AT(runtime.keyframe_periodic_bits_ratio)),
        cost("runtime.padding_bits_ratio", 0.0, 10.0, QVR_HW_AT(runtime.padding_bits_ratio)),
        cost("runtime.corun_slowdown", 1.0, 4.0, QVR_HW_AT(runtime.corun_slowdown)),
        // 0: not measured, corun_slowdown stands.
        cost("runtime.corun_headset_slowdown", 1.0, 4.0, QVR_HW_AT(runtime.corun_headset_slowdown),
             Written::kWhenPositive),
        cost("runtime.corun_server_slowdown", 1.0, 4.0, QVR_HW_AT(runtime.corun_server_slowdown),
             Written::kWhenPositive),
        {"runtime.bits_frame_key", 0.0, 4294967295.0, QVR_HW_AT(runtime.bits_frame_key), "{:.0f}",
         Written::kWithFrameBits, HardwareField::Check::kIntegers, kMaxFrames},
        {"runtime.bits_frame_middle", 0.05, 20.0, QVR_HW_AT(runtime.bits_frame_middle), "{:.4f}",
         Written::kWithFrameBits, HardwareField::Check::kNone, kMaxFrames},
        {"runtime.bits_frame_outer", 0.05, 20.0, QVR_HW_AT(runtime.bits_frame_outer), "{:.4f}",
         Written::kWithFrameBits, HardwareField::Check::kNone, kMaxFrames},
        cost("runtime.speed_reference_headset_ms", 0.0, 1e5,
             QVR_HW_AT(runtime.speed_reference_headset_ms), Written::kWithSpeedReference),
        cost("runtime.speed_reference_server_ms", 0.0, 1e5,
             QVR_HW_AT(runtime.speed_reference_server_ms), Written::kWithSpeedReference),
        {"runtime.speed_reference_key", 0.0, 0.0, QVR_HW_AT(runtime.speed_reference_key), "\"{}\"",
         Written::kWithSpeedReference},
    };
    return f;
}

#undef QVR_HW_POWER_LAW
#undef QVR_HW_AT

// The pipeline key's two words for HardwareConfig::runtime_pipeline.
constexpr std::string_view kPipelineNames[2] = {"paper", "runtime"};

// Reads one key into the config; returns an error for a value the reader's range check cannot
// express (the pipeline's words).
Status readField(ConfigReader& r, const HardwareField& f, HardwareConfig& hw,
                 std::string_view source_name) {
    const HardwareField::Ref ref = f.at(hw);
    if (double* const* v = std::get_if<double*>(&ref)) {
        **v = r.number(f.path, **v, f.min_value, f.max_value);
    } else if (int* const* i = std::get_if<int*>(&ref)) {
        **i = r.integer(f.path, **i, static_cast<int>(f.min_value), static_cast<int>(f.max_value));
    } else if (std::string* const* str = std::get_if<std::string*>(&ref)) {
        **str = r.string(f.path, **str);
    } else if (std::vector<double>* const* arr = std::get_if<std::vector<double>*>(&ref)) {
        if (r.has(f.path))
            **arr = r.numbers(f.path, f.min_value, f.max_value, size_t(f.max_count));
        else
            (void)r.numbers(f.path, f.min_value, f.max_value, size_t(f.max_count));
    } else if (bool* const* b = std::get_if<bool*>(&ref)) {
        const std::string word = r.string(f.path, std::string(kPipelineNames[**b ? 1 : 0]));
        if (word != kPipelineNames[0] && word != kPipelineNames[1])
            return makeError(fmt::format("{}: {} must be \"{}\" or \"{}\", got \"{}\"", source_name,
                                         f.path, kPipelineNames[0], kPipelineNames[1], word));
        **b = word == kPipelineNames[1];
    }
    if (f.check == HardwareField::Check::kEven) {
        const int v = *std::get<int*>(ref);
        if (v % 2 != 0)
            return makeError(fmt::format("{}: {} must be even, got {}", source_name, f.path, v));
    }
    return {};
}

// What the reader's per-key checks cannot see: a key array of integers, and the frame-by-frame
// arrays as long as one another.
Status checkFields(const HardwareConfig& hw, std::string_view source_name) {
    const RuntimeCosts& rc = hw.runtime;
    for (const HardwareField& f : hardwareFields()) {
        if (f.check != HardwareField::Check::kIntegers)
            continue;
        HardwareConfig copy = hw;
        for (double k : *std::get<std::vector<double>*>(f.at(copy)))
            if (k != std::floor(k))
                return makeError(
                    fmt::format("{}: {} must hold integers, got {}", source_name, f.path, k));
    }
    if (rc.bits_frame_middle.size() != rc.bits_frame_key.size() ||
        rc.bits_frame_outer.size() != rc.bits_frame_key.size())
        return makeError(fmt::format(
            "{}: runtime.bits_frame_key, bits_frame_middle and bits_frame_outer must be as long "
            "as one another, got {}, {} and {}",
            source_name, rc.bits_frame_key.size(), rc.bits_frame_middle.size(),
            rc.bits_frame_outer.size()));
    return {};
}

bool isWritten(const HardwareField& f, const HardwareConfig& hw, HardwareField::Ref ref) {
    switch (f.written) {
        case Written::kAlways:
            return true;
        case Written::kWhenPositive:
            return *std::get<double*>(ref) > 0.0;
        case Written::kWithFrameBits:
            return !hw.runtime.bits_frame_key.empty();
        case Written::kWithSpeedReference:
            return hw.runtime.speed_reference_headset_ms > 0.0 &&
                   hw.runtime.speed_reference_server_ms > 0.0;
    }
    return true;
}

std::string fieldValueText(const HardwareField& f, const HardwareField::Ref& ref) {
    if (const double* const* v = std::get_if<double*>(&ref))
        return fmt::format(fmt::runtime(f.format), **v);
    if (const int* const* i = std::get_if<int*>(&ref))
        return fmt::format(fmt::runtime(f.format), **i);
    if (const std::string* const* str = std::get_if<std::string*>(&ref))
        return fmt::format(fmt::runtime(f.format), **str);
    if (const bool* const* b = std::get_if<bool*>(&ref))
        return fmt::format(fmt::runtime(f.format), kPipelineNames[**b ? 1 : 0]);
    std::string s = "[";
    const std::vector<double>& arr = **std::get_if<std::vector<double>*>(&ref);
    for (size_t k = 0; k < arr.size(); ++k)
        s += (k ? ", " : "") + fmt::format(fmt::runtime(f.format), arr[k]);
    return s + "]";
}

}  // namespace

const std::vector<HardwareField>& hardwareFields() {
    static const std::vector<HardwareField> fields = makeHardwareFields();
    return fields;
}

std::string hardwareToml(const HardwareConfig& hw, std::string_view only_section) {
    HardwareConfig copy = hw;  // the fields' references are to a mutable config
    std::string s;
    std::string_view section;
    for (const HardwareField& f : hardwareFields()) {
        const size_t dot = f.path.find('.');
        const std::string_view field_section = f.path.substr(0, dot);
        if (!only_section.empty() && field_section != only_section)
            continue;
        const HardwareField::Ref ref = f.at(copy);
        if (!isWritten(f, copy, ref))
            continue;
        if (field_section != section) {
            section = field_section;
            s += fmt::format("[{}]\n", section);
        }
        s += fmt::format("{} = {}\n", f.path.substr(dot + 1), fieldValueText(f, ref));
    }
    return s;
}

std::string runtimeCostsToml(const RuntimeCosts& costs) {
    HardwareConfig hw;
    hw.runtime_pipeline = true;
    hw.runtime = costs;
    return hardwareToml(hw, "runtime");
}

Expected<HardwareConfig> parseHardwareConfig(std::string_view toml_text,
                                             std::string_view source_name, double gpu_mhz) {
    auto table = parseTomlText(toml_text, source_name);
    if (!table)
        return makeError(table.error());
    HardwareConfig hw = defaultHardware(gpu_mhz);
    ConfigReader r(*table, std::string(source_name));
    for (const HardwareField& f : hardwareFields())
        if (auto st = readField(r, f, hw, source_name); !st)
            return makeError(st.error());
    if (auto st = r.finish(); !st)
        return makeError(st.error());
    if (auto st = checkFields(hw, source_name); !st)
        return makeError(st.error());
    return hw;
}

Expected<HardwareConfig> loadHardwareConfig(const std::string& path, double gpu_mhz) {
    auto text = readTextFile(path);
    if (!text)
        return makeError(text.error());
    return parseHardwareConfig(*text, path, gpu_mhz);
}

}  // namespace qvr
