// `qvr bench uca`: UCA (paper §4.2, Eq. 3–4) against the two-pass reference and the OpenCV
// anchor on both 1920×2160 eyes (compose/uca_benchmark.h; experiment/uca_bench_report.h).
#include <cstdio>
#include <memory>
#include <string>

#include "bench_commands.h"
#include "cli_parse.h"
#include "qvr/experiment/uca_bench_report.h"

namespace qvr::cli {

namespace {

struct UcaBenchCli {
    UcaBenchOptions bench;
    std::string profile = "default";
    bool no_opencv = false;
    bool no_quality = false;
    bool json = false;
};

int runUcaBench(const UcaBenchCli& o) {
    UcaBenchOptions bench = o.bench;
    bench.profile = checkedHmdProfile(o.profile);
    bench.opencv = !o.no_opencv;
    bench.quality = !o.no_quality;
    auto result = runUcaBenchmark(bench);
    if (!result) {
        std::fprintf(stderr, "qvr bench uca: %s\n", result.error().c_str());
        return 1;
    }
    printReport(o.json, experiment::ucaBenchJson(bench, *result),
                experiment::ucaBenchText(bench, *result));
    return 0;
}

}  // namespace

static Registered registerUcaBench(CLI::App& bench) {
    auto o = std::make_shared<UcaBenchCli>();
    UcaBenchOptions& b = o->bench;
    CLI::App* cmd = bench.add_subcommand(
        "uca", "UCA vs two-pass vs OpenCV anchor, bandwidth floor, PSNR/SSIM (paper §4.2)");
    addProfileOption(cmd, o->profile);
    addE1Option(cmd, b.e1_deg, 90.0);
    addFinite(cmd, "--yaw", b.pose_change.yaw_deg,
              "Display pose yaw relative to render pose, degrees", -30.0, 30.0);
    addFinite(cmd, "--pitch", b.pose_change.pitch_deg, "Display pose pitch, degrees", -30.0, 30.0);
    addFinite(cmd, "--roll", b.pose_change.roll_deg, "Display pose roll, degrees", -30.0, 30.0);
    addInt(cmd, "--threads", b.threads, "Worker threads (0: all cores)", 0, 256);
    addInt(cmd, "--iterations", b.iterations, "Timed frames per path (median reported)", 1, 10000);
    cmd->add_flag("--no-opencv", o->no_opencv, "Skip the OpenCV anchor even when built");
    cmd->add_flag("--no-quality", o->no_quality, "Skip the PSNR/SSIM measurement");
    addJsonFlag(cmd, o->json);
    return {cmd, [o]() { return runUcaBench(*o); }};
}

QVR_REGISTER_BENCH(10, registerUcaBench);

}  // namespace qvr::cli
