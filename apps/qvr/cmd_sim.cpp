// `qvr sim`: one design over one workload on one GPU clock and network, through the pipeline
// simulator (paper §5); per-frame records in frames.csv and the run in summary.json.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "options.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/evaluation.h"
#include "qvr/sim/runtime_model.h"
#include "qvr/sim/simulator.h"
#include "qvr/workload/trace_io.h"

namespace qvr::cli {

namespace {

struct SimOptions {
    std::string bench;
    std::string trace;
    std::string design = "qvr";
    double gpu_mhz = 500.0;
    std::string net = "wifi";
    int frames = 300;
    std::string out;
    uint64_t seed = 1;
    std::string hardware;
    std::string pipeline;  // "", "paper" or "runtime"
    int depth = 2;
    double wait_limit_ms = 250.0;
    std::string codec_model = "auto";  // auto: lossless when the trace has it, else stream
};

// The runtime pipeline model (sim/runtime_model.h): frames.csv and summary.json of its own.
int runRuntimeSim(const SimOptions& o, Design design, const HardwareConfig& hw,
                  const WorkloadTrace& trace) {
    if (design == Design::Static) {
        std::fprintf(stderr, "qvr sim: the runtime pipeline has no static design\n");
        return 2;
    }
    RuntimeSimConfig cfg;
    cfg.design = design;
    cfg.costs = hw.runtime;
    cfg.pipeline_depth = o.depth;
    cfg.wait_limit_ms = o.wait_limit_ms;
    cfg.frames = o.frames;
    double delay_ms = 0.0;
    auto link = makeRuntimeLink(o.net, &delay_ms);
    if (!link) {
        std::fprintf(stderr, "qvr sim: --net: %s\n", link.error().c_str());
        return 2;
    }
    cfg.costs.link_delay_ms += delay_ms;
    const RuntimeRunResult run = simulateRuntime(trace, cfg, **link);
    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec) {
        std::fprintf(stderr, "qvr sim: cannot create '%s': %s\n", o.out.c_str(),
                     ec.message().c_str());
        return 1;
    }
    const std::filesystem::path out(o.out);
    std::ofstream csv(out / "frames.csv");
    csv << "frame,e1_deg,pose_ms,decision_ms,request_ms,local_start_ms,local_end_ms,"
           "remote_done_ms,uca_start_ms,uca_end_ms,display_ms,bytes,t_local_ms,t_remote_ms,"
           "headset_busy_ms,mtp_ms,served,reused\n";
    for (const RuntimeFrame& f : run.frames)
        csv << fmt::format(
            "{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.0f},"
            "{:.3f},{:.3f},{:.3f},{:.3f},{},{}\n",
            f.index, f.e1_deg, f.pose_ms, f.decision_ms, f.request_ms, f.local_start_ms,
            f.local_end_ms, f.remote_done_ms, f.uca_start_ms, f.uca_end_ms, f.display_ms, f.bytes,
            f.t_local_ms, f.t_remote_ms, f.headset_busy_ms, f.mtp_ms, int(f.served), int(f.reused));
    const RuntimeSummary& s = run.summary;
    nlohmann::json j = {{"pipeline", "runtime"},
                        {"design", s.design},
                        {"net", o.net},
                        {"pipeline_depth", o.depth},
                        {"frames", s.frames},
                        {"fps_mean", s.fps_mean},
                        {"mtp_ms_mean", s.mtp_ms_mean},
                        {"mtp_ms_p99", s.mtp_ms_p99},
                        {"bytes_per_frame_mean", s.bytes_per_frame_mean},
                        {"e1_deg_mean", s.e1_deg_mean},
                        {"frames_reused", s.frames_reused},
                        {"requests_dropped", s.requests_dropped},
                        {"t_local_ms_mean", s.t_local_ms_mean},
                        {"t_remote_ms_mean", s.t_remote_ms_mean},
                        {"headset_busy_ms_mean", s.headset_busy_ms_mean},
                        {"server_busy_ms_mean", s.server_busy_ms_mean}};
    std::ofstream(out / "summary.json") << j.dump(2) << "\n";
    if (!csv) {
        std::fprintf(stderr, "qvr sim: error writing %s/frames.csv\n", o.out.c_str());
        return 1;
    }
    fmt::print("{} on {} | runtime pipeline, {} in flight | {} | {} frames\n", s.design,
               trace.header.name, o.depth, o.net, s.frames);
    fmt::print("  FPS {:.1f}  MTP {:.1f} ms mean ({:.1f} p99)  {:.0f} B/frame  e1 {:.1f} deg\n",
               s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean, s.e1_deg_mean);
    fmt::print(
        "  headset busy {:.1f} ms/frame  server {:.1f} ms/frame  T_remote {:.1f} ms  reused {}  "
        "dropped requests {}\n",
        s.headset_busy_ms_mean, s.server_busy_ms_mean, s.t_remote_ms_mean, s.frames_reused,
        s.requests_dropped);
    fmt::print("  wrote {}/frames.csv and {}/summary.json\n", o.out, o.out);
    return 0;
}

int runSim(const SimOptions& o) {
    if (o.bench.empty() == o.trace.empty()) {
        std::fprintf(stderr, "qvr sim: give exactly one of --bench NAME or --trace FILE\n");
        return 2;
    }
    auto design = designByName(o.design);
    if (!design) {
        std::fprintf(stderr, "qvr sim: %s\n", design.error().c_str());
        return 2;
    }
    const bool runtime_flag = o.pipeline == "runtime";
    auto net = networkSpecByName(runtime_flag ? std::string("wifi") : o.net);
    if (!net) {
        std::fprintf(stderr, "qvr sim: %s\n", net.error().c_str());
        return 2;
    }
    auto link = makeLink(*net, o.seed);
    if (!link) {
        std::fprintf(stderr, "qvr sim: %s\n", link.error().c_str());
        return 2;
    }
    Expected<WorkloadTrace> trace =
        o.trace.empty() ? makeSuiteBench(o.bench, o.frames) : loadWorkloadTrace(o.trace);
    if (!trace) {
        std::fprintf(stderr, "qvr sim: %s\n", trace.error().c_str());
        return 2;
    }
    // The paper's codec setting when the trace recorded it (docs/MODEL.md, "Codec").
    const CodecModel codec =
        o.codec_model == "auto"
            ? (hasLosslessCodec(*trace) ? CodecModel::kLossless : CodecModel::kStream)
            : *parseCodecModel(o.codec_model);
    if (Status st = applyCodecModel(*trace, codec); !st) {
        std::fprintf(stderr, "qvr sim: %s\n", st.error().c_str());
        return 2;
    }
    if (trace->frames.empty()) {
        std::fprintf(stderr, "qvr sim: the workload has no frames\n");
        return 2;
    }
    HardwareConfig hardware = defaultHardware(o.gpu_mhz);
    if (!o.hardware.empty()) {
        auto hw = loadHardwareConfig(o.hardware, o.gpu_mhz);
        if (!hw) {
            std::fprintf(stderr, "qvr sim: %s\n", hw.error().c_str());
            return 2;
        }
        hardware = *hw;
    }
    if (o.pipeline == "runtime" || (o.pipeline.empty() && hardware.runtime_pipeline))
        return runRuntimeSim(o, *design, hardware, *trace);
    SimConfig cfg;
    cfg.bench = trace->header.name;
    cfg.design = *design;
    cfg.hardware = hardware;
    cfg.frames = o.frames;
    if (static_cast<size_t>(o.frames) > trace->frames.size())
        std::fprintf(stderr, "qvr sim: the trace has %zu frames; simulating all of them\n",
                     trace->frames.size());
    const RunResult run = simulate(*trace, cfg, **link);

    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec) {
        std::fprintf(stderr, "qvr sim: cannot create '%s': %s\n", o.out.c_str(),
                     ec.message().c_str());
        return 1;
    }
    const std::filesystem::path out(o.out);
    if (auto st = writeFramesCsv((out / "frames.csv").string(), run.frames); !st) {
        std::fprintf(stderr, "qvr sim: %s\n", st.error().c_str());
        return 1;
    }
    if (auto st = writeSummaryJson((out / "summary.json").string(), {run.summary}); !st) {
        std::fprintf(stderr, "qvr sim: %s\n", st.error().c_str());
        return 1;
    }
    const RunSummary& s = run.summary;
    fmt::print("{} on {} | GPU {} MHz | {} | {} frames\n", s.design, s.bench, s.gpu_mhz, s.net,
               s.frames);
    fmt::print("  MTP {:.1f} ms mean ({:.1f} p99)  FPS {:.1f} (pipeline {:.1f})\n", s.mtp_ms_mean,
               s.mtp_ms_p99, s.fps_mean, s.fps_pipeline);
    fmt::print("  T_local {:.2f} ms  T_remote {:.2f} ms  T_GPU {:.2f} ms  T_net {:.2f} ms\n",
               s.t_local_ms_mean, s.t_remote_ms_mean, s.gpu_ms_mean, s.net_ms_mean);
    fmt::print(
        "  e1 {:.1f} deg (steady {:.1f})  ratio(final) {:.2f}  {:.0f} KB/frame  {:.2f} "
        "Mpx/frame  {:.1f} mJ/frame\n",
        s.e1_deg_mean, s.e1_deg_steady, s.latency_ratio_final, s.bytes_per_frame_mean / 1e3,
        s.pixels_per_frame_mean / 1e6, s.energy_mj_per_frame);
    fmt::print("  wrote {}/frames.csv and {}/summary.json\n", o.out, o.out);
    return 0;
}

}  // namespace

static Registered registerSim(CLI::App& app) {
    auto o = std::make_shared<SimOptions>();
    CLI::App* cmd = app.add_subcommand(
        "sim", "Simulate one design over one workload on the modelled pipeline (paper §5)");
    cmd->add_option("--bench", o->bench,
                    "Synthetic suite workload: " + suiteBenchNamesList() +
                        " (the 'synthetic-' prefix may be left out)");
    // --bench is parsed first, so with both given the one message says which to drop.
    cmd->add_option("--trace", o->trace, "Workload trace file (JSON lines) instead of --bench")
        ->check(CLI::Validator(
            [o](std::string& path) -> std::string {
                if (!o->bench.empty())
                    return "give exactly one of --bench NAME or --trace FILE";
                return readableFile()(path);
            },
            "FILE", "FILE"));
    cmd->add_option("--design", o->design,
                    "System design: " + designNamesList() +
                        " (local baseline, remote-only, static collaborative, fixed 5-deg fovea, "
                        "LIWC without UCA, software Q-VR, Q-VR)")
        ->capture_default_str();
    cmd->add_option("--gpu-mhz", o->gpu_mhz,
                    "Mobile GPU clock in MHz; the paper uses 500 (default), 400 and 300")
        ->check(finiteRange(50.0, 3000.0))
        ->capture_default_str();
    cmd->add_option("--net", o->net,
                    "Network: wifi (200 Mbps), lte (100), 5g (500), each with 20 dB SNR noise, or "
                    "trace:FILE[@MBPS] for a Mahimahi trace rescaled to MBPS (default 100)")
        ->capture_default_str();
    addFramesOption(cmd, o->frames, 1, 1'000'000, "Frames to simulate (1..1000000)");
    cmd->add_option("--hardware", o->hardware,
                    "TOML file overriding the modelled hardware's constants (docs/MODEL.md)")
        ->check(readableFile());
    cmd->add_option("--pipeline", o->pipeline,
                    "Pipeline model: paper (Fig. 4, the default) or runtime (qvr run's, with the "
                    "hardware file's calibrated costs; the default when that file says so)")
        ->check(CLI::IsMember({"paper", "runtime"}));
    cmd->add_option("--depth", o->depth, "Runtime pipeline: frames in flight (1 or 2)")
        ->check(CLI::Range(1, 2))
        ->capture_default_str();
    cmd->add_option("--wait-limit-ms", o->wait_limit_ms,
                    "Runtime pipeline: remote layers later than this are late (frame reuse)")
        ->check(finiteRange(1.0, 10000.0))
        ->capture_default_str();
    cmd->add_option("--codec-model", o->codec_model,
                    "Periphery bytes from the trace's lossless (the paper's, §2.3) or stream "
                    "(CRF 23) measurements; auto: lossless when recorded")
        ->check(CLI::Validator(
            [](std::string& name) -> std::string {
                if (name == "auto")
                    return {};
                auto model = parseCodecModel(name);
                return model ? std::string() : model.error();
            },
            "auto|lossless|stream", "CODEC_MODEL"))
        ->capture_default_str();
    addSeedOption(cmd, o->seed, "Seed of the network noise");
    cmd->add_option("--out", o->out, "Output folder for frames.csv and summary.json")
        ->required()
        ->check(outputFolder());
    return {cmd, [o]() { return runSim(*o); }};
}

QVR_REGISTER_COMMAND(40, registerSim);

}  // namespace qvr::cli
