// Head-pose traces: interpolation, resampling, placement and CSV (paper §5).
#include "qvr/trace/pose_trace.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "csv_lines.h"
#include "qvr/core/config.h"

namespace qvr {

namespace {
constexpr detail::TimedCsvFormat kPoseCsv{
    .header = "t_ms,qw,qx,qy,qz,x,y,z", .columns = 8, .max_rows = 10'000'000, .rows_name = "poses"};
constexpr double kRadPerDeg = 0.017453292519943295;
}  // namespace

Pose poseAt(const PoseTrace& trace, double t_ms) {
    QVR_CHECK(!trace.samples.empty());
    const auto& s = trace.samples;
    if (t_ms <= s.front().t_ms)
        return s.front().pose;
    if (t_ms >= s.back().t_ms)
        return s.back().pose;
    const auto it = std::upper_bound(s.begin(), s.end(), t_ms,
                                     [](double t, const PoseSample& p) { return t < p.t_ms; });
    const PoseSample& b = *it;
    const PoseSample& a = *(it - 1);
    const float u = static_cast<float>((t_ms - a.t_ms) / (b.t_ms - a.t_ms));
    Pose p;
    p.position_m = glm::mix(a.pose.position_m, b.pose.position_m, u);
    p.orientation = glm::normalize(glm::slerp(a.pose.orientation, b.pose.orientation, u));
    return p;
}

Expected<PoseTrace> resamplePoses(const PoseTrace& trace, double rate_hz, int frames) {
    if (trace.samples.empty())
        return makeError("cannot resample an empty pose trace");
    if (!(rate_hz >= 1.0 && rate_hz <= 1000.0))
        return makeError(fmt::format("rate {} Hz outside [1, 1000]", rate_hz));
    if (frames < 0)
        return makeError("frame count must not be negative");
    const double t0 = trace.samples.front().t_ms;
    const double span_ms = trace.samples.back().t_ms - t0;
    const double step_ms = 1000.0 / rate_hz;
    const int available = static_cast<int>(std::floor(span_ms / step_ms + 1e-9)) + 1;
    if (frames > available)
        return makeError(fmt::format("the motion lasts {:.2f} s: {} frames at {} Hz, {} asked for",
                                     span_ms / 1000.0, available, rate_hz, frames));
    const int n = frames == 0 ? available : frames;
    PoseTrace out;
    out.samples.reserve(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
        const double t = t0 + k * step_ms;
        out.samples.push_back({k * step_ms, poseAt(trace, t)});
    }
    return out;
}

PoseTrace placePoses(const PoseTrace& trace, const glm::vec3& origin_m, double yaw_deg) {
    PoseTrace out = trace;
    if (trace.samples.empty())
        return out;
    const Pose& first = trace.samples.front().pose;
    const double yaw0 = eulerDegFromQuat(first.orientation).yaw_deg;
    const glm::quat turn =
        glm::angleAxis(static_cast<float>((yaw_deg - yaw0) * kRadPerDeg), glm::vec3(0, 1, 0));
    const glm::vec3 start(first.position_m.x, 0.0f, first.position_m.z);
    for (auto& s : out.samples) {
        s.pose.position_m = origin_m + turn * (s.pose.position_m - start);
        s.pose.orientation = glm::normalize(turn * s.pose.orientation);
    }
    return out;
}

PoseTrace smoothPoses(const PoseTrace& trace, double sigma_ms) {
    QVR_CHECK(sigma_ms > 0.0);
    PoseTrace out = trace;
    const auto& s = trace.samples;
    for (size_t i = 0; i < s.size(); ++i) {
        // Weighted mean over ±3 sigma. Quaternions are sign-aligned to the centre one and
        // averaged as vectors: accurate for the few degrees a window spans.
        const double t = s[i].t_ms;
        auto j = static_cast<size_t>(
            std::lower_bound(s.begin(), s.end(), t - 3 * sigma_ms,
                             [](const PoseSample& p, double v) { return p.t_ms < v; }) -
            s.begin());
        const glm::dquat centre(s[i].pose.orientation);
        glm::dvec4 q_sum(0.0);
        glm::dvec3 p_sum(0.0);
        double w_sum = 0.0;
        for (; j < s.size() && s[j].t_ms <= t + 3 * sigma_ms; ++j) {
            const double dt = s[j].t_ms - t;
            const double w = std::exp(-0.5 * dt * dt / (sigma_ms * sigma_ms));
            glm::dquat q(s[j].pose.orientation);
            if (glm::dot(q, centre) < 0.0)
                q = -q;
            q_sum += w * glm::dvec4(q.w, q.x, q.y, q.z);
            p_sum += w * glm::dvec3(s[j].pose.position_m);
            w_sum += w;
        }
        const glm::dquat q = glm::normalize(glm::dquat(q_sum.x, q_sum.y, q_sum.z, q_sum.w));
        out.samples[i].pose.orientation = glm::quat(q);
        out.samples[i].pose.position_m = glm::vec3(p_sum / w_sum);
    }
    return out;
}

std::string poseTraceToCsv(const PoseTrace& trace) {
    return detail::timedCsvText(kPoseCsv, trace.samples, [](const PoseSample& s) {
        const auto& q = s.pose.orientation;
        const auto& p = s.pose.position_m;
        return fmt::format("{:.6f},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", s.t_ms, q.w,
                           q.x, q.y, q.z, p.x, p.y, p.z);
    });
}

Status writePoseCsv(const PoseTrace& trace, const std::string& path) {
    return detail::writeCsvFile(poseTraceToCsv(trace), path);
}

Expected<PoseTrace> parsePoseCsv(std::string_view text, std::string_view source) {
    return detail::parseTimedCsv<PoseTrace>(
        text, source, kPoseCsv,
        [&](const std::vector<double>& r, int line) -> Expected<PoseSample> {
            const double norm = std::sqrt(r[1] * r[1] + r[2] * r[2] + r[3] * r[3] + r[4] * r[4]);
            if (std::fabs(norm - 1.0) > 1e-3)
                return makeError(
                    fmt::format("{}:{}: quaternion norm {} is not 1", source, line, norm));
            for (int c = 5; c < 8; ++c) {
                if (std::fabs(r[static_cast<size_t>(c)]) > 1e6)
                    return makeError(fmt::format("{}:{}: position beyond ±1e6 m", source, line));
            }
            PoseSample s;
            s.t_ms = r[0];
            s.pose.orientation =
                glm::normalize(glm::quat(static_cast<float>(r[1]), static_cast<float>(r[2]),
                                         static_cast<float>(r[3]), static_cast<float>(r[4])));
            s.pose.position_m = glm::vec3(static_cast<float>(r[5]), static_cast<float>(r[6]),
                                          static_cast<float>(r[7]));
            return s;
        });
}

Expected<PoseTrace> loadPoseCsv(const std::string& path) {
    return detail::loadCsvFile(path, kPoseCsv, parsePoseCsv);
}

}  // namespace qvr
