// One `qvr sim` run's inputs, outputs and report (sim_run.h).
#include "qvr/sim/sim_run.h"

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "qvr/core/run_summary_json.h"
#include "qvr/core/text_file.h"
#include "qvr/sim/benches.h"
#include "qvr/sim/evaluation.h"
#include "qvr/workload/trace_io.h"

namespace qvr {

Expected<WorkloadTrace> simWorkload(const std::string& bench, const std::string& trace_path,
                                    int frames, const std::string& codec_model) {
    Expected<WorkloadTrace> trace =
        trace_path.empty() ? makeSuiteBench(bench, frames) : loadWorkloadTrace(trace_path);
    if (!trace)
        return trace;
    // The paper's codec setting when the trace recorded it (docs/MODEL.md, "Codec").
    CodecModel codec = hasLosslessCodec(*trace) ? CodecModel::kLossless : CodecModel::kStream;
    if (codec_model != "auto") {
        auto model = parseCodecModel(codec_model);
        if (!model)
            return makeError(model.error());
        codec = *model;
    }
    if (Status st = applyCodecModel(*trace, codec); !st)
        return makeError(st.error());
    if (trace->frames.empty())
        return makeError("the workload has no frames");
    return trace;
}

Expected<HardwareConfig> simHardware(const std::string& path, double gpu_mhz) {
    if (path.empty())
        return defaultHardware(gpu_mhz);
    return loadHardwareConfig(path, gpu_mhz);
}

namespace {

Status makeFolder(const std::filesystem::path& out) {
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec)
        return makeError("cannot create '" + out.string() + "': " + ec.message());
    return {};
}

}  // namespace

Status writeSimRunOutputs(const std::filesystem::path& out, const RunResult& run) {
    if (Status st = makeFolder(out); !st)
        return st;
    if (Status st = writeFramesCsv((out / "frames.csv").string(), run.frames); !st)
        return st;
    return writeSummaryJson((out / "summary.json").string(), {run.summary});
}

std::string simRunReport(const RunSummary& s, const std::string& out) {
    std::string t = fmt::format("{} on {} | GPU {} MHz | {} | {} frames\n", s.design, s.bench,
                                s.gpu_mhz, s.net, s.frames);
    t += fmt::format("  MTP {:.1f} ms mean ({:.1f} p99)  FPS {:.1f} (pipeline {:.1f})\n",
                     s.mtp_ms_mean, s.mtp_ms_p99, s.fps_mean, s.fps_pipeline);
    t += fmt::format("  T_local {:.2f} ms  T_remote {:.2f} ms  T_GPU {:.2f} ms  T_net {:.2f} ms\n",
                     s.t_local_ms_mean, s.t_remote_ms_mean, s.gpu_ms_mean, s.net_ms_mean);
    t += fmt::format(
        "  e1 {:.1f} deg (steady {:.1f})  ratio(final) {:.2f}  {:.0f} KB/frame  {:.2f} "
        "Mpx/frame  {:.1f} mJ/frame\n",
        s.e1_deg_mean, s.e1_deg_steady, s.latency_ratio_final, s.bytes_per_frame_mean / 1e3,
        s.pixels_per_frame_mean / 1e6, s.energy_mj_per_frame);
    t += fmt::format("  wrote {}/frames.csv and {}/summary.json\n", out, out);
    return t;
}

Expected<RuntimeRunResult> simulateRuntimePipeline(const WorkloadTrace& trace, Design design,
                                                   const HardwareConfig& hw,
                                                   const RuntimeSimSetting& setting) {
    if (design == Design::Static)
        return makeError("the runtime pipeline has no static design");
    RuntimeSimConfig cfg;
    cfg.design = design;
    cfg.costs = hw.runtime;
    cfg.pipeline_depth = setting.pipeline_depth;
    cfg.wait_limit_ms = setting.wait_limit_ms;
    cfg.frames = setting.frames;
    double delay_ms = 0.0;
    auto link = makeRuntimeLink(setting.net, &delay_ms);
    if (!link)
        return makeError("--net: " + link.error());
    cfg.costs.link_delay_ms += delay_ms;
    return simulateRuntime(trace, cfg, **link);
}

Status writeRuntimeSimOutputs(const std::filesystem::path& out, const RuntimeRunResult& run,
                              const RuntimeSimSetting& setting) {
    if (Status st = makeFolder(out); !st)
        return st;
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
    nlohmann::json j = runStatsJson(s);
    j.update({{"pipeline", "runtime"},
              {"design", s.design},
              {"net", setting.net},
              {"pipeline_depth", setting.pipeline_depth},
              {"requests_dropped", s.requests_dropped},
              {"requests_withheld", s.requests_withheld},
              {"t_local_ms_mean", s.t_local_ms_mean},
              {"t_remote_ms_mean", s.t_remote_ms_mean},
              {"headset_busy_ms_mean", s.headset_busy_ms_mean},
              {"server_busy_ms_mean", s.server_busy_ms_mean}});
    const Status summary = writeJsonFile((out / "summary.json").string(), j);
    if (!csv)
        return makeError("error writing " + out.string() + "/frames.csv");
    return summary;
}

std::string runtimeSimReport(const RuntimeSummary& s, const std::string& bench,
                             const RuntimeSimSetting& setting, const std::string& out) {
    std::string t = fmt::format("{} on {} | runtime pipeline, {} in flight | {} | {} frames\n",
                                s.design, bench, setting.pipeline_depth, setting.net, s.frames);
    t += fmt::format(
        "  FPS {:.1f}  MTP {:.1f} ms mean ({:.1f} p99)  {:.0f} B/frame  e1 {:.1f} deg\n",
        s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean, s.e1_deg_mean);
    t += fmt::format(
        "  headset busy {:.1f} ms/frame  server {:.1f} ms/frame  T_remote {:.1f} ms  reused {}  "
        "dropped requests {}\n",
        s.headset_busy_ms_mean, s.server_busy_ms_mean, s.t_remote_ms_mean, s.frames_reused,
        s.requests_dropped);
    t += fmt::format("  wrote {}/frames.csv and {}/summary.json\n", out, out);
    return t;
}

}  // namespace qvr
