// `qvr bench uca`: UCA (paper §4.2, Eq. 3–4) against the two-pass reference and the OpenCV
// anchor on both 1920×2160 eyes, with the copy-bandwidth floor and PSNR/SSIM to ground truth.
#if defined(QVR_HAVE_COMPOSE)
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_commands.h"
#include "options.h"
#include "qvr/compose/opencv_two_pass.h"
#include "qvr/compose/uca_benchmark.h"
#include "qvr/experiment/host.h"

namespace qvr::cli {

namespace {

struct UcaBenchCli {
    std::string profile = "default";
    double e1_deg = 15.0;
    double yaw_deg = 2.0;
    double pitch_deg = 1.0;
    double roll_deg = 0.5;
    int threads = 2;
    int iterations = 21;
    bool no_opencv = false;
    bool no_quality = false;
    bool json = false;
};

nlohmann::json regionJson(const RegionQuality& q) {
    return {{"psnr_db", std::isfinite(q.psnr_db) ? q.psnr_db : 999.0},
            {"ssim", q.ssim},
            {"pixels", q.pixels}};
}

nlohmann::json qualityJson(const QualityReport& q) {
    return {{"fovea", regionJson(q.fovea)},
            {"periphery", regionJson(q.periphery)},
            {"all", regionJson(q.all)}};
}

}  // namespace

static Registered registerUcaBench(CLI::App& bench) {
    auto opts = std::make_shared<UcaBenchCli>();
    CLI::App* cmd = bench.add_subcommand(
        "uca", "UCA vs two-pass vs OpenCV anchor, bandwidth floor, PSNR/SSIM (paper §4.2)");
    addProfileOption(cmd, opts->profile);
    cmd->add_option("--e1", opts->e1_deg, "Fovea radius e1 in degrees")
        ->check(finiteRange(0.0, 90.0))
        ->capture_default_str();
    cmd->add_option("--yaw", opts->yaw_deg, "Display pose yaw relative to render pose, degrees")
        ->check(finiteRange(-30.0, 30.0))
        ->capture_default_str();
    cmd->add_option("--pitch", opts->pitch_deg, "Display pose pitch, degrees")
        ->check(finiteRange(-30.0, 30.0))
        ->capture_default_str();
    cmd->add_option("--roll", opts->roll_deg, "Display pose roll, degrees")
        ->check(finiteRange(-30.0, 30.0))
        ->capture_default_str();
    cmd->add_option("--threads", opts->threads, "Worker threads (0: all cores)")
        ->check(CLI::Range(0, 256))
        ->capture_default_str();
    cmd->add_option("--iterations", opts->iterations, "Timed frames per path (median reported)")
        ->check(CLI::Range(1, 10000))
        ->capture_default_str();
    cmd->add_flag("--no-opencv", opts->no_opencv, "Skip the OpenCV anchor even when built");
    cmd->add_flag("--no-quality", opts->no_quality, "Skip the PSNR/SSIM measurement");
    cmd->add_flag("--json", opts->json, "Print machine-readable JSON");
    Action action = [opts]() -> int {
        auto profile = hmdProfileByName(opts->profile);
        if (!profile) {
            std::fprintf(stderr, "qvr bench uca: %s\n", profile.error().c_str());
            return 2;
        }
        UcaBenchOptions o;
        o.profile = *profile;
        o.e1_deg = opts->e1_deg;
        o.pose_change = {opts->yaw_deg, opts->pitch_deg, opts->roll_deg};
        o.threads = opts->threads;
        o.iterations = opts->iterations;
        o.opencv = !opts->no_opencv;
        o.quality = !opts->no_quality;
        auto r = runUcaBenchmark(o);
        if (!r) {
            std::fprintf(stderr, "qvr bench uca: %s\n", r.error().c_str());
            return 1;
        }
        const UcaBenchResult& b = *r;
        if (opts->json) {
            nlohmann::json j;
            j["uca_ms"] = b.uca_ms;
            j["two_pass_ms"] = b.two_pass_ms;
            if (b.opencv_two_pass_ms)
                j["opencv_two_pass_ms"] = *b.opencv_two_pass_ms;
            j["bandwidth_floor_ms"] = b.bandwidth_floor_ms;
            if (o.quality) {
                j["psnr_uca_db"] = b.uca_quality.all.psnr_db;
                j["psnr_two_pass_db"] = b.two_pass_quality.all.psnr_db;
                j["quality"] = {{"uca", qualityJson(b.uca_quality)},
                                {"two_pass", qualityJson(b.two_pass_quality)}};
                if (b.opencv_quality)
                    j["quality"]["opencv_two_pass"] = qualityJson(*b.opencv_quality);
                j["quality_vs_layers"] = {{"uca", qualityJson(b.uca_vs_layers)},
                                          {"two_pass", qualityJson(b.two_pass_vs_layers)}};
                if (b.opencv_vs_layers) {
                    j["quality_vs_layers"]["opencv_two_pass"] = qualityJson(*b.opencv_vs_layers);
                }
            }
            j["uca_min_ms"] = b.uca_min_ms;
            j["two_pass_min_ms"] = b.two_pass_min_ms;
            if (b.opencv_two_pass_min_ms)
                j["opencv_two_pass_min_ms"] = *b.opencv_two_pass_min_ms;
            j["bandwidth_floor_min_ms"] = b.bandwidth_floor_min_ms;
            j["uca_scalar_ms"] = b.uca_scalar_ms;
            j["uca_bytes"] = b.uca_bytes;
            j["copy_gbps"] = b.copy_gbps;
            j["tiles"] = {
                {"empty", b.tiles.empty}, {"single", b.tiles.single}, {"border", b.tiles.border}};
            j["config"] = {{"profile", o.profile.name},
                           {"width_px", o.profile.width_px},
                           {"height_px", o.profile.height_px},
                           {"eyes", 2},
                           {"e1_deg", o.e1_deg},
                           {"pose_change_deg", b.pose_change_deg},
                           {"threads", b.threads},
                           {"iterations", o.iterations},
                           {"simd_target", b.simd_target},
                           {"opencv_built", openCvAnchorBuilt()},
                           {"cpu", experiment::cpuModel()},
                           {"hardware_threads", std::thread::hardware_concurrency()},
                           {"load_average", experiment::loadAverage1()}};
            std::printf("%s\n", j.dump(2).c_str());
            return 0;
        }
        fmt::print(
            "UCA benchmark: {}x{} per eye, both eyes, e1 {} deg, pose change {:.2f} deg, "
            "{} threads, SIMD {}\n",
            o.profile.width_px, o.profile.height_px, o.e1_deg, b.pose_change_deg, b.threads,
            b.simd_target);
        fmt::print("  tiles: {} empty, {} single-layer, {} border; load average {:.2f}\n",
                   b.tiles.empty, b.tiles.single, b.tiles.border, experiment::loadAverage1());
        fmt::print("  ms per frame        median      min   ({} frames each)\n", o.iterations);
        fmt::print("  UCA                {:8.2f} {:8.2f}\n", b.uca_ms, b.uca_min_ms);
        fmt::print("  UCA scalar twin    {:8.2f}\n", b.uca_scalar_ms);
        fmt::print("  two-pass reference {:8.2f} {:8.2f}   UCA speed-up {:.2f}x (min {:.2f}x)\n",
                   b.two_pass_ms, b.two_pass_min_ms, b.two_pass_ms / b.uca_ms,
                   b.two_pass_min_ms / b.uca_min_ms);
        if (b.opencv_two_pass_ms) {
            fmt::print(
                "  OpenCV two-pass    {:8.2f} {:8.2f}   UCA speed-up {:.2f}x (min {:.2f}x)\n",
                *b.opencv_two_pass_ms, *b.opencv_two_pass_min_ms, *b.opencv_two_pass_ms / b.uca_ms,
                *b.opencv_two_pass_min_ms / b.uca_min_ms);
        } else {
            fmt::print("  OpenCV two-pass    not built (configure with -DQVR_WITH_OPENCV=ON)\n");
        }
        fmt::print(
            "  bandwidth floor    {:8.2f} {:8.2f}   {:.1f} MB at {:.1f} GB/s (median copy); "
            "UCA is {:.2f}x the floor (min {:.2f}x)\n",
            b.bandwidth_floor_ms, b.bandwidth_floor_min_ms, b.uca_bytes / 1e6, b.copy_gbps,
            b.uca_ms / b.bandwidth_floor_ms, b.uca_min_ms / b.bandwidth_floor_min_ms);
        if (o.quality) {
            auto row = [](const char* name, const QualityReport& q) {
                fmt::print(
                    "  {:<9} PSNR fovea {:7.3f} dB  periphery {:7.3f} dB  all {:7.3f} dB   "
                    "SSIM fovea {:.5f}  periphery {:.5f}\n",
                    name, q.fovea.psnr_db, q.periphery.psnr_db, q.all.psnr_db, q.fovea.ssim,
                    q.periphery.ssim);
            };
            fmt::print("  against the full-resolution render warped in double (ground truth):\n");
            row("UCA", b.uca_quality);
            row("two-pass", b.two_pass_quality);
            if (b.opencv_quality)
                row("OpenCV", *b.opencv_quality);
            fmt::print("  against the layers' own Eq. 4 in double (filtering error alone):\n");
            row("UCA", b.uca_vs_layers);
            row("two-pass", b.two_pass_vs_layers);
            if (b.opencv_vs_layers)
                row("OpenCV", *b.opencv_vs_layers);
        }
        return 0;
    };
    return {cmd, action};
}

QVR_REGISTER_BENCH(10, registerUcaBench);

}  // namespace qvr::cli
#endif
