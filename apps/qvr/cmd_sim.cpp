// `qvr sim`: one design over one workload on one GPU clock and network, through the pipeline
// simulator (paper §5); per-frame records in frames.csv and the run in summary.json.
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "command_error.h"
#include "commands.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/network.h"
#include "qvr/sim/sim_run.h"

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
    const RuntimeSimSetting setting{o.net, o.depth, o.wait_limit_ms, o.frames};
    auto run = simulateRuntimePipeline(trace, design, hw, setting);
    if (!run)
        return fail("sim", run.error(), 2);
    if (Status st = writeRuntimeSimOutputs(o.out, *run, setting); !st)
        return fail("sim", st.error(), 1);
    fmt::print("{}", runtimeSimReport(run->summary, trace.header.name, setting, o.out));
    return 0;
}

int runSim(const SimOptions& o) {
    if (o.bench.empty() == o.trace.empty())
        return fail("sim", "give exactly one of --bench NAME or --trace FILE", 2);
    auto design = designByName(o.design);
    if (!design)
        return fail("sim", design.error(), 2);
    auto net = networkSpecByName(o.pipeline == "runtime" ? std::string("wifi") : o.net);
    auto link = net ? makeLink(*net, o.seed) : makeError(net.error());
    auto trace =
        link ? simWorkload(o.bench, o.trace, o.frames, o.codec_model) : makeError(link.error());
    auto hardware = trace ? simHardware(o.hardware, o.gpu_mhz) : makeError(trace.error());
    if (!hardware)
        return fail("sim", hardware.error(), 2);
    if (o.pipeline == "runtime" || (o.pipeline.empty() && hardware->runtime_pipeline))
        return runRuntimeSim(o, *design, *hardware, *trace);
    SimConfig cfg;
    cfg.bench = trace->header.name;
    cfg.design = *design;
    cfg.hardware = *hardware;
    cfg.frames = o.frames;
    if (static_cast<size_t>(o.frames) > trace->frames.size())
        std::fprintf(stderr, "qvr sim: the trace has %zu frames; simulating all of them\n",
                     trace->frames.size());
    const RunResult run = simulate(*trace, cfg, **link);
    if (Status st = writeSimRunOutputs(o.out, run); !st)
        return fail("sim", st.error(), 1);
    fmt::print("{}", simRunReport(run.summary, o.out));
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
    addFinite(cmd, "--gpu-mhz", o->gpu_mhz,
              "Mobile GPU clock in MHz; the paper uses 500 (default), 400 and 300", 50.0, 3000.0);
    cmd->add_option("--net", o->net,
                    "Network: wifi (200 Mbps), lte (100), 5g (500), each with 20 dB SNR noise, or "
                    "trace:FILE[@MBPS] for a Mahimahi trace rescaled to MBPS (default 100)")
        ->capture_default_str();
    addFramesOption(cmd, o->frames, 1, 1'000'000, "Frames to simulate (1..1000000)");
    addHardwareOption(cmd, o->hardware, kHardwareOverrideHelp);
    cmd->add_option("--pipeline", o->pipeline,
                    "Pipeline model: paper (Fig. 4, the default) or runtime (qvr run's, with the "
                    "hardware file's calibrated costs; the default when that file says so)")
        ->check(CLI::IsMember({"paper", "runtime"}));
    addInt(cmd, "--depth", o->depth, "Runtime pipeline: frames in flight (1 or 2)", 1, 2);
    addFinite(cmd, "--wait-limit-ms", o->wait_limit_ms,
              "Runtime pipeline: remote layers later than this are late (frame reuse)", 1.0,
              10000.0);
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
    addOutputFolderOption(cmd, o->out, "Output folder for frames.csv and summary.json")->required();
    return {cmd, [o]() { return runSim(*o); }};
}

QVR_REGISTER_COMMAND(40, registerSim);

}  // namespace qvr::cli
