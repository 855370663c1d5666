// The headset and server hardware the simulator times frames on (paper Table 2, §4.3, §5): a
// mobile GPU whose rates scale with its clock, two UCA units, a video decoder, a CPU for the
// control logic, and a multi-GPU render server. Every constant's source is in docs/MODEL.md.
#pragma once

#include <algorithm>
#include <cmath>

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/workload/cost_model.h"

namespace qvr {

// The mobile GPU beyond its render rates (GpuModel): the screen-space passes composition and
// ATW run as, and its power. Table 2: 8 unified shaders, one texture unit each; a bilinear
// texture unit returns one filtered sample per cycle, so a full-screen filtering pass is bound
// by 8 samples per cycle.
struct MobileGpuConfig {
    GpuModel render;                          // freq_mhz lives here
    double texture_units = 8.0;               // Table 2: 8 shaders × 1 texture unit
    double samples_per_unit_per_cycle = 1.0;  // bilinear filter throughput of one unit
    double pass_overhead_ms = 0.1;            // kernel launch + tile-buffer flush per pass
    double preempt_overhead_ms = 0.05;        // context save/restore when a pass preempts LR
    double atw_samples_per_px = 1.0;          // one distorted bilinear fetch per output pixel
    double comp_samples_per_px = 1.0;         // foveated: each pixel reads the layer covering it
    double static_comp_samples_per_px = 2.0;  // static: background colour + depth per pixel
    // Power: P_dyn = P_dyn_ref · (f / f_ref) · (V(f) / V(f_ref))², V(f) = v0 + v_slope · f.
    double dynamic_power_w_at_500 = 2.5;
    double static_power_w_at_500 = 0.3;  // leakage, ∝ V
    double v0 = 0.55;
    double v_per_mhz = 0.0005;

    double samplesPerMs() const;
    // One full-screen pass over `pixels` output pixels at `samples_per_px` texture fetches each.
    double passMs(double pixels, double samples_per_px) const;
    double voltage(double freq_mhz) const { return v0 + v_per_mhz * freq_mhz; }
    double dynamicPowerW() const;
    double staticPowerW() const;
};

// The Unified Composition and ATW unit (§4.2–4.3): 532 cycles per 32×32 tile, two units at
// 500 MHz, 94 mW each while busy.
struct UcaConfig {
    int units = 2;
    double freq_mhz = 500.0;
    double cycles_per_tile = 532.0;
    int tile_px = 32;
    double power_w = 0.094;

    double tileMs() const { return cycles_per_tile / (freq_mhz * 1e3); }  // one tile, one unit
    // Wall time for `tiles` tiles spread over all units.
    double wallMs(double tiles) const { return tiles * tileMs() / units; }
};

// LIWC (§4.1, §4.3): a table lookup in nanoseconds, 25 mW.
struct LiwcHwConfig {
    double decision_ms = 100e-6;  // 100 ns
    double power_w = 0.025;
};

// The headset's hardware video decoder and the server's render and encode rates. The server is
// the chiplet multi-GPU of [64]; its render, the encode, the transfer and the decode stream in
// parallel, so a frame's remote latency is the largest of them (§2.3).
struct RemoteConfig {
    double server_speedup = 64.0;          // 8 GPU modules × 8× one mobile GPU at 500 MHz
    double encoder_px_per_ms = 1.0e6;      // per stream; each layer of each eye is its own stream
    double decoder_px_per_ms = 531'000.0;  // 4096×2160 at 60 fps
    double decode_overhead_ms = 0.2;
};

// The CPU's per-frame work (Fig. 4 CL and LS).
struct CpuConfig {
    double control_logic_ms = 1.0;     // application logic on the new pose
    double local_setup_ms = 0.5;       // command buffers for the local layer, issue remote fetch
    double software_control_ms = 0.3;  // sw design: read back GPU timers, pick e1 on the CPU
};

// Fixed latencies outside the pipeline (§5): sensor to engine, and display scan-out.
struct FixedLatencies {
    double sensor_ms = 2.0;
    double display_ms = 5.0;
};

// ---- The runtime pipeline model (runtime_model.h): this machine's costs, from `qvr calibrate`.

// One part's cost in ms for a pass over `pixels` drawing `triangles`: the linear law
// a + b·Mpx + c·ktri, or, when power_coef_ms > 0, the power law k·Mpx^p·ktri^q (llvmpipe's
// fovea pass is not linear in either over 3 kpx … 4 Mpx: MODEL.md §9). A whole frame (local's
// pass, remote's layer) costs full_frame_scale × the law: the law is fitted to the fovea and
// periphery layers, the whole frame is measured on its own. `qvr calibrate` fits all of it.
struct PartCost {
    double base_ms = 0.0;
    double ms_per_mpx = 0.0;     // per million pixels
    double ms_per_ktri = 0.0;    // per thousand triangles (as the scene's BVH counts them)
    double power_coef_ms = 0.0;  // > 0: the power law replaces the linear one
    double px_exponent = 0.0;
    double tri_exponent = 0.0;
    double full_frame_scale = 1.0;
    // > 0: the linear law also charges the fragments the pass shades (its overdraw), per million
    // (docs/MODEL.md §9). A pass whose fragments are not
    // known (< 0) is charged frag_per_px of them per pixel, the calibration samples' mean.
    double ms_per_mfrag = 0.0;
    double frag_per_px = 0.0;
    double at(double pixels, double triangles, double fragments = -1.0) const {
        if (power_coef_ms > 0.0)
            return power_coef_ms * std::pow(std::max(pixels * 1e-6, 1e-6), px_exponent) *
                   std::pow(std::max(triangles * 1e-3, 0.01), tri_exponent);
        const double frag_ms =
            ms_per_mfrag > 0.0
                ? ms_per_mfrag * (fragments >= 0.0 ? fragments : pixels * frag_per_px) * 1e-6
                : 0.0;
        return base_ms + ms_per_mpx * pixels * 1e-6 + ms_per_ktri * triangles * 1e-3 + frag_ms;
    }
    double atFullFrame(double pixels, double triangles, double fragments = -1.0) const {
        return full_frame_scale * at(pixels, triangles, fragments);
    }
};

// Factors on the calibrated times of each side, the headset's and the server's (1: as
// calibrated): a machine slower than at its calibration (the speed probes), a share of a core, N
// headsets on one server (RuntimeCosts::atSpeed takes them).
struct SideFactors {
    double headset = 1.0;
    double server = 1.0;
};

// This machine's costs of the runtime's parts. The defaults are placeholders of the right order
// for llvmpipe on one core of a 2-core Xeon (so tests and an uncalibrated `qvr sim --model
// runtime` run); a calibration replaces every one of them.
struct RuntimeCosts {
    // Headset, one core.
    PartCost decision{0.5, 0.0, 0.04};  // BVH ring counts to e1 + 6°: triangles counted
    PartCost fovea{2.0, 50.0, 0.02};    // one eye's fovea (or full frame) render pass
    PartCost decode{0.3, 4.0, 0.0};     // one stream, per decoded layer pixel
    PartCost uca{5.0, 1.3, 0.0};        // one frame: base + per layer pixel read (both eyes)
    double frame_overhead_ms = 0.5;     // per frame: pumps, telemetry, bookkeeping
    // Per frame, when the run records its display video (qvr run --video, RuntimeSimConfig::
    // record_scanout): the quarter-resolution copy of the scan-out, after the frame is queued.
    double scanout_record_ms = 0.0;
    // The codec's P-frame size on the calibration's scene: bits per layer pixel b·s^γ at scale
    // s. 0: take bits per pixel from the workload trace instead.
    double bits_per_px_at_1 = 0.0;
    double bits_scale_exponent = 0.0;
    // The outer layer's own law (bits_outer_per_px_at_1 > 0); 0: the one above for both. At the
    // same scale the outer layer takes ~0.6× the middle's bits per pixel (measured, MODEL.md §9).
    double bits_outer_per_px_at_1 = 0.0;
    double bits_outer_scale_exponent = 0.0;
    // remote's whole frame (one layer per eye at scale 1), measured on its own (> 0); 0: the
    // law above at scale 1. The law, fitted to periphery layers at scales ~2.5–12, put 0.27
    // bits on a whole-frame pixel where a default run's remote frames carried 0.126.
    double bits_full_frame_per_px = 0.0;
    // Bits per layer pixel of a P-frame at scale s of the middle (or whole-frame) or outer layer.
    double bitsPerPx(double scale, bool outer) const {
        const bool own = outer && bits_outer_per_px_at_1 > 0.0;
        return (own ? bits_outer_per_px_at_1 : bits_per_px_at_1) *
               std::pow(std::max(scale, 1.0),
                        own ? bits_outer_scale_exponent : bits_scale_exponent);
    }
    // The laws above are a mean over the calibration's motion; its frames do not cost alike (a
    // default run's first second looks at denser geometry: its P-frames 12–15% over the mean).
    // Frame by frame, on the calibration's own motion: bits_frame_key[k] is frame k's content
    // key (frameContentKey of its head pose, 0: none measured) and
    // bits_frame_middle[k] / bits_frame_outer[k] what its periphery layers spent over the law
    // (docs/MODEL.md §10). Empty: the law alone.
    std::vector<double> bits_frame_key;
    std::vector<double> bits_frame_middle;
    std::vector<double> bits_frame_outer;
    // Whether the calibration coded this very content as its frame k.
    bool bitsFrameMeasured(size_t frame, uint32_t content_key) const {
        return frame < bits_frame_key.size() && bits_frame_key[frame] != 0.0 &&
               bits_frame_key[frame] == double(content_key);
    }
    // Frame k's factor on the law (1 unless the calibration coded this very content at frame k).
    double bitsFrameFactor(size_t frame, uint32_t content_key, bool outer) const {
        if (!bitsFrameMeasured(frame, content_key))
            return 1.0;
        const std::vector<double>& f = outer ? bits_frame_outer : bits_frame_middle;
        return frame < f.size() ? f[frame] : 1.0;
    }
    // Each stream's canvas and key frames as the x264 encoder makes them (codec/video_codec.h
    // CodecConfig, core/canvas_policy.h), replayed per stream: a P-frame in a canvas larger than
    // the snug one the bits law was measured in pays padding_bits_ratio of a layer pixel's bits
    // for each extra canvas pixel (relative to the snug canvas); a canvas change, and every
    // keyint_frames-th frame of an encoder, is an IDR of keyframe_bits_ratio (middle or whole
    // frame) or keyframe_outer_bits_ratio (outer) times the P-frame's bits (a new encoder's first
    // frame; the periodic one keyframe_periodic_bits_ratio). keyframe_bits_ratio
    // 0: no canvas model (every frame a P-frame of a snug canvas, calibration version ≤ 6).
    int canvas_align_px = 16;
    double canvas_headroom = 0.10;
    double canvas_shrink_ratio = 0.5;
    int canvas_shrink_after_frames = 30;
    int keyint_frames = 120;  // 0: no periodic IDR
    double keyframe_bits_ratio = 0.0;
    double keyframe_outer_bits_ratio = 0.0;
    // The periodic IDR of a running encoder (keyint_frames) costs less than a new encoder's
    // first frame; 0: the new encoder's ratio.
    double keyframe_periodic_bits_ratio = 0.0;
    double padding_bits_ratio = 0.0;
    // Server, one core (render thread): per layer render and encode, and per request.
    PartCost server_render{2.0, 60.0, 0.01};
    PartCost encode{0.5, 12.0, 0.0};
    double server_frame_ms = 0.0;
    // Link: media packets carry this much payload and this much header on the wire.
    double packet_payload_bytes = 1200.0;
    double packet_overhead_bytes = 48.0;
    double link_delay_ms = 0.0;  // one way
    // The two cores at once: work on one side while the other side is busy takes this many
    // times as long as alone (both sides slow alike; measured by `qvr calibrate` as a layer
    // render's median with a second core rendering without pause over its median alone). 1: the
    // sides do not disturb each other. docs/MODEL.md §11.
    double corun_slowdown = 1.0;
    // Per side (0: corun_slowdown for that side): the headset's work (fovea, decodes, UCA) while
    // the server works, and the server's (layer renders, read-back, encodes) while the headset
    // works. Their mixes differ in what they ask of the memory both cores share, so each is
    // measured beside the other's mix (docs/MODEL.md §11).
    double corun_headset_slowdown = 0.0;
    double corun_server_slowdown = 0.0;
    double headsetCoRun() const {
        return corun_headset_slowdown > 0.0 ? corun_headset_slowdown : corun_slowdown;
    }
    double serverCoRun() const {
        return corun_server_slowdown > 0.0 ? corun_server_slowdown : corun_slowdown;
    }
    double payloadShare() const {
        return packet_payload_bytes / (packet_payload_bytes + packet_overhead_bytes);
    }
    // The machine's speed when the costs above were measured: the
    // median of a fixed headset frame and a fixed server frame (a speed probe, `qvr calibrate`
    // SpeedProbe) over the calibration, 0: not measured. speed_reference_key names what the
    // probe ran (scene, profile, codec, level of detail): a probe at run time on the same key
    // says how much faster or slower the machine is than when it was calibrated
    // (docs/MODEL.md §11).
    double speed_reference_headset_ms = 0.0;
    double speed_reference_server_ms = 0.0;
    std::string speed_reference_key;
    // These costs on a machine `headset` and `server` times as slow as the calibration's: every
    // time the headset's core spends (decision, fovea, decodes, UCA, the frame's overhead, the
    // video copy) times `headset`, every time the server's (layer render, encode, per request)
    // times `server`. Bits, the link and the co-running ratios are not times and stay.
    RuntimeCosts atSpeed(double headset, double server) const {
        RuntimeCosts c = *this;
        auto scale = [](PartCost& p, double f) {
            p.base_ms *= f;
            p.ms_per_mpx *= f;
            p.ms_per_ktri *= f;
            p.power_coef_ms *= f;
            p.ms_per_mfrag *= f;
        };
        for (PartCost* p : {&c.decision, &c.fovea, &c.decode, &c.uca})
            scale(*p, headset);
        c.frame_overhead_ms *= headset;
        c.scanout_record_ms *= headset;
        scale(c.server_render, server);
        scale(c.encode, server);
        c.server_frame_ms *= server;
        return c;
    }
};

struct HardwareConfig {
    MobileGpuConfig gpu;
    UcaConfig uca;
    LiwcHwConfig liwc;
    RemoteConfig remote;
    CpuConfig cpu;
    FixedLatencies fixed;
    // Which pipeline `qvr sim` times frames on: the paper's (false, the default) or the
    // runtime's as built, with `runtime`'s costs (a calibration file sets it).
    bool runtime_pipeline = false;
    RuntimeCosts runtime;
};

// The defaults of docs/MODEL.md at a given GPU clock.
HardwareConfig defaultHardware(double gpu_mhz = 500.0);

// One key of the hardware file: its dotted path, where it lives in HardwareConfig, the values it
// accepts and how and when the writer writes it. hardwareFields() is the file's grammar, in the
// order the writer writes it: parseHardwareConfig and hardwareToml both walk it, so a key is
// added in one place.
struct HardwareField {
    // runtime.pipeline is the one bool: "paper" (false) or "runtime" (true).
    using Ref = std::variant<double*, int*, bool*, std::string*, std::vector<double>*>;
    // When hardwareToml writes the key: always; when the value is > 0 (0: not measured, and the
    // reader refuses it); with the frame-by-frame bits (bits_frame_key not empty); with a speed
    // reference (both probe times > 0).
    enum class Written { kAlways, kWhenPositive, kWithFrameBits, kWithSpeedReference };
    // A check beyond the range: an even integer, an array of integers.
    enum class Check { kNone, kEven, kIntegers };

    std::string_view path;                    // "section.key"
    double min_value = 0.0, max_value = 0.0;  // numbers, integers and array elements
    Ref (*at)(HardwareConfig&) = nullptr;
    std::string_view format = "{}";  // fmt format of one value (of each element of an array)
    Written written = Written::kAlways;
    Check check = Check::kNone;
    double max_count = 0.0;  // arrays: at most this many values
};
const std::vector<HardwareField>& hardwareFields();

// Overrides of the defaults from TOML, so a researcher can ask about another headset without
// recompiling. Every key is optional; unknown keys and out-of-range values are errors naming the
// key. The clock stays a command-line choice (`--gpu-mhz`), since `qvr eval` sweeps it. The
// sections are [gpu], [uca], [liwc], [remote], [cpu], [latency] (the paper's hardware, keys named
// as HardwareConfig's members) and [runtime] (pipeline = "paper" or "runtime", and RuntimeCosts:
// every cost in ms within 0…10000, a PartCost's key its part and member, e.g. fovea_ms_per_mpx;
// canvas_align_px even; bits_frame_key integers, as long as bits_frame_middle and
// bits_frame_outer). Each key's range is its row in hardwareFields() (hardware.cpp).
Expected<HardwareConfig> parseHardwareConfig(std::string_view toml_text,
                                             std::string_view source_name, double gpu_mhz);
Expected<HardwareConfig> loadHardwareConfig(const std::string& path, double gpu_mhz);

// The hardware file for `hw`, every key hardwareFields() writes, or only those of one section
// ("runtime"); parseHardwareConfig reads it back to `hw` (calibrated costs kept to six
// significant digits).
std::string hardwareToml(const HardwareConfig& hw, std::string_view only_section = {});

// The [runtime] section for these costs (pipeline = "runtime"): what `qvr calibrate` writes.
std::string runtimeCostsToml(const RuntimeCosts& costs);

}  // namespace qvr
