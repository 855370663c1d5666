// `qvr capacity`: headsets per render server at a target frame rate, from a calibration and a
// workload through the calibrated runtime model (sim/capacity.h holds the model and its limits).
#include <algorithm>
#include <cstdio>
#include <memory>

#include <fmt/format.h>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/core/design.h"
#include "qvr/core/text_file.h"
#include "qvr/experiment/prediction.h"
#include "qvr/render/draw_list.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/sim/capacity.h"

namespace qvr::cli {

namespace {

struct CapacityCmdOptions {
    std::string hardware, trace, design = "qvr", json, scene;
    float lod_px = 1.0f;
    CapacityOptions model;
};

// With --scene, the layers' triangles as the renderer draws them at the trace's head poses (what
// qvr run's prediction charges); without, the trace's ring counts.
Expected<CapacityLayerTriangles> drawnTriangles(const CapacityCmdOptions& o,
                                                const WorkloadTrace& trace) {
    if (o.scene.empty())
        return CapacityLayerTriangles{};
    auto scene = loadScene(o.scene);
    if (!scene)
        return makeError("--scene: " + scene.error());
    auto list = std::make_shared<DrawList>(buildDrawList(*scene));
    if (o.lod_px > 0.0f)
        buildLods(*list, *scene);
    auto heads = std::make_shared<std::vector<Pose>>();
    for (const WorkloadFrame& f : trace.frames)
        heads->push_back(f.head);
    return experiment::drawnLayerTriangles(
        std::move(list), trace.header.profile, o.lod_px, true, [heads](int64_t frame) {
            return (*heads)[size_t(std::clamp<int64_t>(frame, 0, int64_t(heads->size()) - 1))];
        });
}

int runCapacity(CapacityCmdOptions& o) {
    auto design = parseDesign(o.design, DesignScope::Runtime);
    if (!design) {
        std::fprintf(stderr, "qvr capacity: --design: %s\n", design.error().c_str());
        return 2;
    }
    o.model.design = design->design;
    o.model.fixed_e1_deg = design->fixed_e1_deg;
    auto in = loadCapacityInputs(o.hardware, o.trace);
    if (!in) {
        std::fprintf(stderr, "qvr capacity: %s\n", in.error().c_str());
        return 2;
    }
    auto triangles = drawnTriangles(o, in->trace);
    if (!triangles) {
        std::fprintf(stderr, "qvr capacity: %s\n", triangles.error().c_str());
        return 2;
    }
    auto r = predictCapacity(in->trace, in->costs, o.model, *triangles);
    if (!r) {
        std::fprintf(stderr, "qvr capacity: %s\n", r.error().c_str());
        return 2;
    }
    fmt::print("{}", capacityText(*r, o.model));
    if (!o.json.empty())
        if (Status st = writeTextFile(o.json, capacityJson(*r, o.model)); !st) {
            std::fprintf(stderr, "qvr capacity: %s\n", st.error().c_str());
            return 1;
        }
    return 0;
}

}  // namespace

static Registered registerCapacity(CLI::App& app) {
    auto o = std::make_shared<CapacityCmdOptions>();
    CLI::App* cmd = app.add_subcommand(
        "capacity", "Headsets per render server at a target FPS (the calibrated runtime model)");
    addHardwareOption(cmd, o->hardware, "Calibration (qvr calibrate --out FILE)")->required();
    cmd->add_option("--trace", o->trace, "Workload (a qvr run's workload.jsonl, data/workloads/)")
        ->required()
        ->check(readableFile());
    cmd->add_option("--target-fps", o->model.target_fps, "Every headset's frame-rate floor")
        ->required()
        ->check(finiteRange(0.1, 1000.0));
    cmd->add_option("--scene", o->scene,
                    "The workload's scene: count the triangles each layer draws at its poses "
                    "(level of detail, holes), as qvr run's prediction does (default: the trace's "
                    "ring counts)");
    addLodOption(cmd, o->lod_px);
    cmd->add_option("--design", o->design, "Runtime design (qvr, ffr, fixed:E, remote, …)")
        ->capture_default_str();
    cmd->add_option("--net", o->model.net, "Each headset's link (qvr run --net)")
        ->capture_default_str();
    addFinite(cmd, "--headset-share", o->model.headset_share,
              "Each headset's share of its core (qvr run --headset-share)", 0.01, 1.0);
    cmd->add_flag("--headsets-share-one-core", o->model.headsets_share_one_core,
                  "The headsets take turns on one core (qvr run --headsets on this machine)");
    cmd->add_option("--max-headsets", o->model.max_headsets)->check(CLI::Range(1, 64));
    cmd->add_flag("--every-count", o->model.every_count, "Every count up to --max-headsets");
    addFramesOption(cmd, o->model.frames, 20, 100000, "Frames each count is modelled over");
    addFinite(cmd, "--headset-speed", o->model.speed.headset,
              "The headset's times over the calibration's on this machine now (a qvr run's "
              "summary.json calibration.speed_reference.run_over_reference.headset)",
              0.05, 20.0);
    addFinite(cmd, "--server-speed", o->model.speed.server,
              "The server's times over the calibration's (run_over_reference.server)", 0.05, 20.0);
    cmd->add_option("--json", o->json, "Write the result as JSON");
    return {cmd, [o] { return runCapacity(*o); }};
}

QVR_REGISTER_COMMAND(94, registerCapacity);

}  // namespace qvr::cli
