#include "qvr/trace/record_report.h"

#include <fmt/format.h>

namespace qvr {

std::string recordingHeadline(const RecordOptions& o, const RecordInputs& inputs,
                              const std::string& renderer) {
    return fmt::format(
        "{} ({} triangles, {} batches, {} spawn points), {}x{} at {} Hz, {} frames, {}\n",
        inputs.scene.name, inputs.scene.triangleCount(), inputs.scene.batches.size(),
        inputs.scene.spawns.size(), o.profile.width_px, o.profile.height_px, o.profile.refresh_hz,
        o.frames, renderer);
}

std::string recordProgressLine(const RecordProgress& p, bool terminal) {
    const double per_frame = p.elapsed_s / static_cast<double>(p.frame);
    const double eta = per_frame * static_cast<double>(p.frames - p.frame);
    if (terminal)
        return fmt::format("\r  frame {}/{}  {:.2f} s/frame  ETA {:.0f} s   ", p.frame, p.frames,
                           per_frame, eta);
    if (p.frame % 10 == 0 || p.frame == p.frames)
        return fmt::format("  frame {}/{}  {:.2f} s/frame  ETA {:.0f} s\n", p.frame, p.frames,
                           per_frame, eta);
    return {};
}

std::string recordingDoneLine(const RecordResult& r, const std::string& out_path) {
    return fmt::format("wrote {}: {} frames of {} in {:.1f} s ({:.2f} s/frame)\n", out_path,
                       r.frames_written, r.header.name, r.elapsed_s,
                       r.elapsed_s / static_cast<double>(r.frames_written));
}

}  // namespace qvr
