// Workload trace files: JSON lines (docs/WORKLOAD_FORMAT.md). The reader treats every byte as
// untrusted: bounded line length, bounded counts, every field type- and range-checked, and the
// line number in every error.
#include "qvr/workload/trace_io.h"

#include <cmath>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>
#include <type_traits>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace qvr {

namespace {

using nlohmann::json;

constexpr int kFormatVersion = 1;
constexpr size_t kMaxLineBytes = size_t{4} << 20;

// Field readers: return false (and set an error) instead of throwing.
struct FieldReader {
    std::string error;

    // A number in [lo, hi] (an integer when T is one); absent is an error only when required.
    template <typename T>
    bool ranged(const json& obj, const char* key, T& out, T lo, T hi, bool required) {
        constexpr bool kInteger = std::is_integral_v<T>;
        const auto it = obj.find(key);
        if (it == obj.end()) {
            if (required)
                error = fmt::format("missing '{}'", key);
            return !required;
        }
        if (kInteger ? !it->is_number_integer() : !it->is_number()) {
            error = fmt::format("'{}' must be {}", key, kInteger ? "an integer" : "a number");
            return false;
        }
        const T v = it->get<T>();
        bool finite = true;
        if constexpr (!kInteger)
            finite = std::isfinite(v);
        if (!finite || v < lo || v > hi) {
            error = fmt::format("'{}' = {} is outside [{}, {}]", key, v, lo, hi);
            return false;
        }
        out = v;
        return true;
    }
    bool number(const json& obj, const char* key, double& out, double lo, double hi,
                bool required = true) {
        return ranged(obj, key, out, lo, hi, required);
    }
    bool integer(const json& obj, const char* key, int64_t& out, int64_t lo, int64_t hi,
                 bool required = true) {
        return ranged(obj, key, out, lo, hi, required);
    }
    bool string(const json& obj, const char* key, std::string& out) {
        const auto it = obj.find(key);
        if (it == obj.end())
            return true;
        if (!it->is_string()) {
            error = fmt::format("'{}' must be a string", key);
            return false;
        }
        out = it->get<std::string>();
        if (out.size() > 4096) {
            error = fmt::format("'{}' is longer than 4096 bytes", key);
            return false;
        }
        return true;
    }
    bool array(const json& obj, const char* key, std::vector<double>& out, size_t expected_size,
               size_t max_size) {
        const auto it = obj.find(key);
        if (it == obj.end()) {
            error = fmt::format("missing '{}'", key);
            return false;
        }
        if (!it->is_array()) {
            error = fmt::format("'{}' must be an array", key);
            return false;
        }
        if (it->size() > max_size || (expected_size != 0 && it->size() != expected_size)) {
            error = fmt::format("'{}' has {} values, expected {}", key, it->size(),
                                expected_size != 0 ? expected_size : max_size);
            return false;
        }
        out.clear();
        out.reserve(it->size());
        for (const auto& v : *it) {
            if (!v.is_number()) {
                error = fmt::format("'{}' must hold only numbers", key);
                return false;
            }
            const double d = v.get<double>();
            if (!std::isfinite(d)) {
                error = fmt::format("'{}' holds a non-finite value", key);
                return false;
            }
            out.push_back(d);
        }
        return true;
    }
    bool object(const json& obj, const char* key, const json*& out) {
        const auto it = obj.find(key);
        if (it == obj.end() || !it->is_object()) {
            error = fmt::format("missing object '{}'", key);
            return false;
        }
        out = &*it;
        return true;
    }
};

// Reads one line of at most kMaxLineBytes; returns false at end of input.
bool readLine(std::istream& in, std::string& line, bool& too_long) {
    line.clear();
    too_long = false;
    char c;
    bool any = false;
    while (in.get(c)) {
        any = true;
        if (c == '\n')
            return true;
        if (line.size() >= kMaxLineBytes) {
            too_long = true;
            // Skip the rest of the line.
            while (in.get(c) && c != '\n') {
            }
            return true;
        }
        line.push_back(c);
    }
    return any;
}

bool parseHeader(const json& j, WorkloadHeader& h, FieldReader& r) {
    std::string format;
    if (!r.string(j, "format", format))
        return false;
    if (format != "qvr-workload") {
        r.error = "not a qvr workload trace (format must be \"qvr-workload\")";
        return false;
    }
    int64_t version = 0;
    if (!r.integer(j, "version", version, 1, 1000))
        return false;
    if (version != kFormatVersion) {
        r.error =
            fmt::format("unsupported version {} (this qvr reads {})", version, kFormatVersion);
        return false;
    }
    if (!r.string(j, "name", h.name) || !r.string(j, "source", h.source))
        return false;
    const json* p = nullptr;
    if (!r.object(j, "profile", p))
        return false;
    HmdProfile& prof = h.profile;
    int64_t w = 0, hh = 0;
    if (!r.string(*p, "name", prof.name) || !r.integer(*p, "width_px", w, 16, 16384) ||
        !r.integer(*p, "height_px", hh, 16, 16384) ||
        !r.number(*p, "fov_h_deg", prof.fov_h_deg, 10, 170) ||
        !r.number(*p, "fov_v_deg", prof.fov_v_deg, 10, 170) ||
        !r.number(*p, "refresh_hz", prof.refresh_hz, 1, 1000))
        return false;
    prof.width_px = static_cast<int>(w);
    prof.height_px = static_cast<int>(hh);
    if (const auto lens = p->find("lens"); lens != p->end() && lens->is_object()) {
        if (!r.number(*lens, "k1", prof.lens.k1, -1, 4, false) ||
            !r.number(*lens, "k2", prof.lens.k2, -1, 4, false) ||
            !r.number(*lens, "chroma_red_scale", prof.lens.chroma_red_scale, 0.9, 1.1, false) ||
            !r.number(*lens, "chroma_blue_scale", prof.lens.chroma_blue_scale, 0.9, 1.1, false))
            return false;
    }
    if (const auto ac = p->find("acuity"); ac != p->end() && ac->is_object()) {
        if (!r.number(*ac, "omega0_deg", prof.acuity.omega0_deg, 1e-4, 1, false) ||
            !r.number(*ac, "slope", prof.acuity.slope, 0, 1, false))
            return false;
    }
    int64_t rings = 0, batches = 0;
    if (!r.number(j, "ring_deg", h.ring_deg, 1e-3, 10) ||
        !r.integer(j, "rings", rings, 1, kMaxRings) ||
        !r.array(j, "scales", h.scales, 0, kMaxScales) ||
        !r.integer(j, "batches", batches, 0, 10'000'000, false))
        return false;
    h.rings = static_cast<int>(rings);
    h.batches = static_cast<int>(batches);
    return true;
}

bool parseFrame(const json& j, const WorkloadHeader& h, WorkloadFrame& f, FieldReader& r) {
    if (!r.integer(j, "i", f.index, 0, kMaxTraceFrames) ||
        !r.number(j, "t_ms", f.time_ms, -1e12, 1e12))
        return false;
    const json* head = nullptr;
    if (!r.object(j, "head", head))
        return false;
    std::vector<double> q, p, g;
    if (!r.array(*head, "q", q, 4, 4) || !r.array(*head, "p", p, 3, 3))
        return false;
    const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(qn > 0.9 && qn < 1.1)) {
        r.error = fmt::format("head quaternion has norm {}, expected 1", qn);
        return false;
    }
    f.head.orientation = glm::quat(static_cast<float>(q[0] / qn), static_cast<float>(q[1] / qn),
                                   static_cast<float>(q[2] / qn), static_cast<float>(q[3] / qn));
    f.head.position_m =
        glm::vec3(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
    if (!r.array(j, "gaze", g, 2, 2))
        return false;
    f.gaze = {g[0], g[1]};
    const size_t rings = static_cast<size_t>(h.rings);
    if (!r.array(j, "tri", f.triangles_per_ring, rings, rings) ||
        !r.array(j, "pix", f.pixels_per_ring, rings, rings) ||
        !r.array(j, "bpp", f.bits_per_pixel, h.scales.size(), h.scales.size()))
        return false;
    if (j.contains("bpp_lossless") &&
        !r.array(j, "bpp_lossless", f.bits_per_pixel_lossless, h.scales.size(), h.scales.size()))
        return false;
    if (!r.number(j, "frag_px", f.fovea_fragments_per_px, 0, 1e3, false))
        return false;
    const json* st = nullptr;
    if (!r.object(j, "static", st))
        return false;
    StaticSplit& s = f.static_split;
    return r.number(*st, "fg_tri", s.fg_triangles, 0, 1e12) &&
           r.number(*st, "fg_frac", s.fg_screen_fraction, 0, 1) &&
           r.number(*st, "bg_bytes", s.bg_bytes, 0, 1e12) &&
           r.number(*st, "depth_bytes", s.depth_bytes, 0, 1e12) &&
           r.number(*st, "bg_bytes_lossless", s.bg_bytes_lossless, 0, 1e12, false);
}

json vec(const std::vector<double>& v) {
    return json(v);
}

}  // namespace

Expected<WorkloadTrace> readWorkloadTrace(std::istream& in, const std::string& source_name) {
    WorkloadTrace trace;
    std::string line;
    bool too_long = false;
    int64_t line_no = 0;
    bool have_header = false;
    double last_time_ms = -std::numeric_limits<double>::infinity();
    FieldReader r;
    auto fail = [&](const std::string& what) {
        return makeError(fmt::format("{}:{}: {}", source_name, line_no, what));
    };
    while (readLine(in, line, too_long)) {
        ++line_no;
        if (too_long)
            return fail(fmt::format("line longer than {} bytes", kMaxLineBytes));
        if (line.find_first_not_of(" \t\r") == std::string::npos)
            continue;
        const json j = json::parse(line, nullptr, /*allow_exceptions=*/false);
        if (j.is_discarded())
            return fail("not valid JSON");
        if (!j.is_object())
            return fail("each line must be a JSON object");
        if (!have_header) {
            if (!parseHeader(j, trace.header, r))
                return fail(r.error);
            if (auto st = validateHeader(trace.header); !st)
                return fail(st.error());
            have_header = true;
            continue;
        }
        if (static_cast<int64_t>(trace.frames.size()) >= kMaxTraceFrames)
            return fail(fmt::format("more than {} frames", kMaxTraceFrames));
        WorkloadFrame f;
        if (!parseFrame(j, trace.header, f, r))
            return fail(r.error);
        if (auto st = validateFrame(trace.header, f, last_time_ms); !st)
            return fail(st.error());
        last_time_ms = f.time_ms;
        trace.frames.push_back(std::move(f));
    }
    if (in.bad())
        return makeError(fmt::format("{}: read error", source_name));
    if (!have_header)
        return makeError(fmt::format("{}: empty file, no header", source_name));
    if (trace.frames.empty())
        return makeError(fmt::format("{}: no frames", source_name));
    if (auto st = validateTrace(trace); !st)
        return makeError(fmt::format("{}: {}", source_name, st.error()));
    return trace;
}

Expected<WorkloadTrace> loadWorkloadTrace(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return makeError(fmt::format("cannot open workload trace '{}'", path));
    return readWorkloadTrace(in, path);
}

WorkloadTraceWriter::WorkloadTraceWriter(std::ostream& out) : m_out(out) {}

void WorkloadTraceWriter::writeHeader(const WorkloadHeader& h) {
    const HmdProfile& p = h.profile;
    json j = {{"format", "qvr-workload"},
              {"version", kFormatVersion},
              {"name", h.name},
              {"source", h.source},
              {"profile",
               {{"name", p.name},
                {"width_px", p.width_px},
                {"height_px", p.height_px},
                {"fov_h_deg", p.fov_h_deg},
                {"fov_v_deg", p.fov_v_deg},
                {"refresh_hz", p.refresh_hz},
                {"lens",
                 {{"k1", p.lens.k1},
                  {"k2", p.lens.k2},
                  {"chroma_red_scale", p.lens.chroma_red_scale},
                  {"chroma_blue_scale", p.lens.chroma_blue_scale}}},
                {"acuity", {{"omega0_deg", p.acuity.omega0_deg}, {"slope", p.acuity.slope}}}}},
              {"ring_deg", h.ring_deg},
              {"rings", h.rings},
              {"scales", vec(h.scales)},
              {"batches", h.batches}};
    m_out << j.dump() << '\n';
    m_out.flush();
    m_header_copy = h;
    m_header = &m_header_copy;
}

void WorkloadTraceWriter::writeFrame(const WorkloadFrame& f) {
    QVR_CHECK_MSG(m_header != nullptr, "writeHeader() first");
    const glm::quat& q = f.head.orientation;
    const glm::vec3& p = f.head.position_m;
    json j = {{"i", f.index},
              {"t_ms", f.time_ms},
              {"head", {{"q", {q.w, q.x, q.y, q.z}}, {"p", {p.x, p.y, p.z}}}},
              {"gaze", {f.gaze.x_deg, f.gaze.y_deg}},
              {"tri", vec(f.triangles_per_ring)},
              {"pix", vec(f.pixels_per_ring)},
              {"bpp", vec(f.bits_per_pixel)},
              {"static",
               {{"fg_tri", f.static_split.fg_triangles},
                {"fg_frac", f.static_split.fg_screen_fraction},
                {"bg_bytes", f.static_split.bg_bytes},
                {"depth_bytes", f.static_split.depth_bytes}}}};
    if (!f.bits_per_pixel_lossless.empty())
        j["bpp_lossless"] = vec(f.bits_per_pixel_lossless);
    if (f.fovea_fragments_per_px >= 0.0)
        j["frag_px"] = f.fovea_fragments_per_px;
    if (f.static_split.bg_bytes_lossless >= 0.0)
        j["static"]["bg_bytes_lossless"] = f.static_split.bg_bytes_lossless;
    m_out << j.dump() << '\n';
    m_out.flush();
}

Status saveWorkloadTrace(const WorkloadTrace& trace, const std::string& path) {
    if (auto st = validateTrace(trace); !st)
        return st;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out)
        return makeError(fmt::format("cannot write '{}'", path));
    WorkloadTraceWriter w(out);
    w.writeHeader(trace.header);
    for (const auto& f : trace.frames)
        w.writeFrame(f);
    if (!out)
        return makeError(fmt::format("error writing '{}'", path));
    return Status::success();
}

}  // namespace qvr
