#include "qvr/experiment/uca_bench_report.h"

#include <cmath>
#include <thread>

#include <fmt/format.h>

#include "qvr/compose/opencv_two_pass.h"
#include "qvr/experiment/host.h"

namespace qvr::experiment {

namespace {

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

// Each path's quality against one reference, under the JSON key `key`.
void addQuality(nlohmann::json& j, const char* key, const QualityReport& uca,
                const QualityReport& two_pass, const std::optional<QualityReport>& opencv) {
    j[key] = {{"uca", qualityJson(uca)}, {"two_pass", qualityJson(two_pass)}};
    if (opencv)
        j[key]["opencv_two_pass"] = qualityJson(*opencv);
}

}  // namespace

nlohmann::json ucaBenchJson(const UcaBenchOptions& o, const UcaBenchResult& b) {
    nlohmann::json j;
    j["uca_ms"] = b.uca_ms;
    j["two_pass_ms"] = b.two_pass_ms;
    if (b.opencv_two_pass_ms)
        j["opencv_two_pass_ms"] = *b.opencv_two_pass_ms;
    j["bandwidth_floor_ms"] = b.bandwidth_floor_ms;
    if (o.quality) {
        j["psnr_uca_db"] = b.uca_quality.all.psnr_db;
        j["psnr_two_pass_db"] = b.two_pass_quality.all.psnr_db;
        addQuality(j, "quality", b.uca_quality, b.two_pass_quality, b.opencv_quality);
        addQuality(j, "quality_vs_layers", b.uca_vs_layers, b.two_pass_vs_layers,
                   b.opencv_vs_layers);
    }
    j["uca_min_ms"] = b.uca_min_ms;
    j["two_pass_min_ms"] = b.two_pass_min_ms;
    if (b.opencv_two_pass_min_ms)
        j["opencv_two_pass_min_ms"] = *b.opencv_two_pass_min_ms;
    j["bandwidth_floor_min_ms"] = b.bandwidth_floor_min_ms;
    j["uca_scalar_ms"] = b.uca_scalar_ms;
    j["uca_bytes"] = b.uca_bytes;
    j["copy_gbps"] = b.copy_gbps;
    j["tiles"] = {{"empty", b.tiles.empty}, {"single", b.tiles.single}, {"border", b.tiles.border}};
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
                   {"cpu", cpuModel()},
                   {"hardware_threads", std::thread::hardware_concurrency()},
                   {"load_average", loadAverage1()}};
    return j;
}

std::string ucaBenchText(const UcaBenchOptions& o, const UcaBenchResult& b) {
    std::string out = fmt::format(
        "UCA benchmark: {}x{} per eye, both eyes, e1 {} deg, pose change {:.2f} deg, "
        "{} threads, SIMD {}\n",
        o.profile.width_px, o.profile.height_px, o.e1_deg, b.pose_change_deg, b.threads,
        b.simd_target);
    out += fmt::format("  tiles: {} empty, {} single-layer, {} border; load average {:.2f}\n",
                       b.tiles.empty, b.tiles.single, b.tiles.border, loadAverage1());
    out += fmt::format("  ms per frame        median      min   ({} frames each)\n", o.iterations);
    out += fmt::format("  UCA                {:8.2f} {:8.2f}\n", b.uca_ms, b.uca_min_ms);
    out += fmt::format("  UCA scalar twin    {:8.2f}\n", b.uca_scalar_ms);
    auto speedup = [&](const char* name, double ms, double min_ms) {
        return fmt::format("  {:<18} {:8.2f} {:8.2f}   UCA speed-up {:.2f}x (min {:.2f}x)\n", name,
                           ms, min_ms, ms / b.uca_ms, min_ms / b.uca_min_ms);
    };
    out += speedup("two-pass reference", b.two_pass_ms, b.two_pass_min_ms);
    out += b.opencv_two_pass_ms
               ? speedup("OpenCV two-pass", *b.opencv_two_pass_ms, *b.opencv_two_pass_min_ms)
               : "  OpenCV two-pass    not built (configure with -DQVR_WITH_OPENCV=ON)\n";
    out += fmt::format(
        "  bandwidth floor    {:8.2f} {:8.2f}   {:.1f} MB at {:.1f} GB/s (median copy); "
        "UCA is {:.2f}x the floor (min {:.2f}x)\n",
        b.bandwidth_floor_ms, b.bandwidth_floor_min_ms, b.uca_bytes / 1e6, b.copy_gbps,
        b.uca_ms / b.bandwidth_floor_ms, b.uca_min_ms / b.bandwidth_floor_min_ms);
    if (!o.quality)
        return out;
    auto row = [&out](const char* name, const QualityReport& q) {
        out += fmt::format(
            "  {:<9} PSNR fovea {:7.3f} dB  periphery {:7.3f} dB  all {:7.3f} dB   "
            "SSIM fovea {:.5f}  periphery {:.5f}\n",
            name, q.fovea.psnr_db, q.periphery.psnr_db, q.all.psnr_db, q.fovea.ssim,
            q.periphery.ssim);
    };
    out += "  against the full-resolution render warped in double (ground truth):\n";
    row("UCA", b.uca_quality);
    row("two-pass", b.two_pass_quality);
    if (b.opencv_quality)
        row("OpenCV", *b.opencv_quality);
    out += "  against the layers' own Eq. 4 in double (filtering error alone):\n";
    row("UCA", b.uca_vs_layers);
    row("two-pass", b.two_pass_vs_layers);
    if (b.opencv_vs_layers)
        row("OpenCV", *b.opencv_vs_layers);
    return out;
}

}  // namespace qvr::experiment
