// BVH reader (paper §5: real head motion for the workloads). The grammar, as accepted:
//
//   file      := "HIERARCHY" joint "MOTION" "Frames:" N "Frame Time:" T frame{N}
//   joint     := ("ROOT" | "JOINT") NAME "{" "OFFSET" x y z "CHANNELS" n channel{n}
//                (joint | endsite)* "}"
//   endsite   := "End" "Site" "{" "OFFSET" x y z "}"
//   channel   := Xposition | Yposition | Zposition | Xrotation | Yrotation | Zrotation
//   frame     := one line of exactly (sum of n) numbers
//
// Rotations are in degrees. Every count is bounded (BvhLimits) and every error names its line.
#include "qvr/trace/bvh.h"

#include <charconv>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "qvr/core/config.h"

namespace qvr {

namespace {

constexpr double kRadPerDeg = 0.017453292519943295;

struct Token {
    std::string_view text;
    int line = 0;  // initialised: GCC -O3 (Release) otherwise warns maybe-uninitialized
};

// Splits the hierarchy section into tokens (braces are tokens even when glued to a word).
class HierarchyLexer {
public:
    explicit HierarchyLexer(std::string_view text) : m_text(text) {}

    bool next(Token& t) {
        while (m_pos < m_text.size()) {
            const char c = m_text[m_pos];
            if (c == '\n') {
                ++m_line;
                ++m_pos;
            } else if (c == ' ' || c == '\t' || c == '\r') {
                ++m_pos;
            } else {
                break;
            }
        }
        if (m_pos >= m_text.size())
            return false;
        const size_t start = m_pos;
        if (m_text[m_pos] == '{' || m_text[m_pos] == '}') {
            ++m_pos;
        } else {
            while (m_pos < m_text.size()) {
                const char c = m_text[m_pos];
                if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '{' || c == '}')
                    break;
                ++m_pos;
            }
        }
        t = {m_text.substr(start, m_pos - start), m_line};
        return true;
    }
    size_t pos() const { return m_pos; }
    int line() const { return m_line; }

private:
    std::string_view m_text;
    size_t m_pos = 0;
    int m_line = 1;
};

bool parseNumber(std::string_view s, double& out) {
    if (s.empty() || s.size() > 64)
        return false;
    // from_chars rejects a leading '+', and BVH writers emit ".0083333": accept both.
    if (s[0] == '+')
        s.remove_prefix(1);
    const char* end = s.data() + s.size();
    auto r = std::from_chars(s.data(), end, out);
    return r.ec == std::errc() && r.ptr == end && std::isfinite(out);
}

// The next space- or tab-separated token of row from position i (moved past it); empty at the
// end of the row.
std::string_view nextToken(std::string_view row, size_t& i) {
    while (i < row.size() && (row[i] == ' ' || row[i] == '\t'))
        ++i;
    const size_t start = i;
    while (i < row.size() && row[i] != ' ' && row[i] != '\t')
        ++i;
    return row.substr(start, i - start);
}

// Whitespace-separated numbers in a line, or -1 if any token is not a number.
int countNumbers(std::string_view row) {
    int n = 0;
    size_t i = 0;
    for (std::string_view token = nextToken(row, i); !token.empty(); token = nextToken(row, i)) {
        double v = 0;
        if (!parseNumber(token, v))
            return -1;
        ++n;
    }
    return n;
}

class Parser {
public:
    Parser(std::string_view text, std::string_view source, const BvhLimits& limits)
        : m_lex(text), m_text(text), m_source(source), m_limits(limits) {}

    Expected<BvhMotion> run() {
        if (m_text.size() > m_limits.max_bytes)
            return fail(1, fmt::format("file larger than {} bytes", m_limits.max_bytes));
        Token t;
        if (!m_lex.next(t) || t.text != "HIERARCHY")
            return fail(t.line, "expected HIERARCHY at the start");
        if (!m_lex.next(t) || t.text != "ROOT")
            return fail(m_lex.line(), "expected ROOT after HIERARCHY");
        if (Status s = joint(-1, 0); !s)
            return makeError(s.error());
        if (!m_lex.next(t))
            return fail(m_lex.line(), "missing MOTION section (file ends after the hierarchy)");
        if (t.text == "ROOT")
            return fail(t.line, "more than one ROOT: only single-skeleton files are supported");
        if (t.text != "MOTION")
            return fail(t.line, fmt::format("expected MOTION, found '{}'", clip(t.text)));
        return motion(t.line);
    }

private:
    Error fail(int line, const std::string& what) const {
        return makeError(fmt::format("{}:{}: {}", m_source, line, what));
    }
    static std::string clip(std::string_view s) {
        return std::string(s.substr(0, 40)) + (s.size() > 40 ? "…" : "");
    }

    Status expect(std::string_view word) {
        Token t;
        if (!m_lex.next(t))
            return fail(m_lex.line(), fmt::format("file ends where '{}' was expected", word));
        if (t.text != word)
            return fail(t.line, fmt::format("expected '{}', found '{}'", word, clip(t.text)));
        return Status::success();
    }

    Status vec3(glm::dvec3& v) {
        for (int i = 0; i < 3; ++i) {
            Token t;
            if (!m_lex.next(t))
                return fail(m_lex.line(), "file ends inside OFFSET");
            double x = 0;
            if (!parseNumber(t.text, x) || std::fabs(x) > m_limits.max_abs_value)
                return fail(t.line, fmt::format("OFFSET value '{}' is not a number within ±{}",
                                                clip(t.text), m_limits.max_abs_value));
            v[i] = x;
        }
        return Status::success();
    }

    Status joint(int parent, int depth) {
        if (depth >= m_limits.max_depth)
            return fail(m_lex.line(),
                        fmt::format("joints nested deeper than {}", m_limits.max_depth));
        if (static_cast<int>(m_out.joints.size()) >= m_limits.max_joints)
            return fail(m_lex.line(), fmt::format("more than {} joints", m_limits.max_joints));
        Token name;
        if (!m_lex.next(name) || name.text == "{")
            return fail(name.line, "joint without a name");
        if (name.text.size() > m_limits.max_name_chars)
            return fail(name.line, "joint name too long");
        BvhJoint j;
        j.name = std::string(name.text);
        j.parent = parent;
        if (Status s = expect("{"); !s)
            return s;
        if (Status s = expect("OFFSET"); !s)
            return s;
        if (Status s = vec3(j.offset); !s)
            return s;
        if (Status s = expect("CHANNELS"); !s)
            return s;
        Token count_tok;
        if (!m_lex.next(count_tok))
            return fail(m_lex.line(), "file ends after CHANNELS");
        double count = -1;
        if (!parseNumber(count_tok.text, count) || count != std::floor(count) || count < 0 ||
            count > 6)
            return fail(count_tok.line,
                        fmt::format("CHANNELS count '{}' is not 0 to 6", clip(count_tok.text)));
        int seen = 0;
        for (int i = 0; i < static_cast<int>(count); ++i) {
            Token c;
            if (!m_lex.next(c))
                return fail(m_lex.line(), "file ends inside CHANNELS");
            static constexpr std::string_view kNames[] = {"Xposition", "Yposition", "Zposition",
                                                          "Xrotation", "Yrotation", "Zrotation"};
            int which = -1;
            for (int k = 0; k < 6; ++k) {
                if (c.text == kNames[k])
                    which = k;
            }
            if (which < 0)
                return fail(c.line, fmt::format("'{}' is not a channel name (CHANNELS says {} "
                                                "channels)",
                                                clip(c.text), static_cast<int>(count)));
            if (seen & (1 << which))
                return fail(c.line, fmt::format("channel {} listed twice", kNames[which]));
            seen |= 1 << which;
            j.channels.push_back(static_cast<BvhChannel>(which));
        }
        j.first_channel = m_out.channel_count;
        m_out.channel_count += static_cast<int>(j.channels.size());
        const int index = static_cast<int>(m_out.joints.size());
        m_out.joints.push_back(std::move(j));
        for (;;) {
            Token t;
            if (!m_lex.next(t))
                return fail(m_lex.line(),
                            fmt::format("file ends inside joint '{}' (missing '}}')",
                                        m_out.joints[static_cast<size_t>(index)].name));
            if (t.text == "}")
                return Status::success();
            if (t.text == "JOINT") {
                if (Status s = joint(index, depth + 1); !s)
                    return s;
            } else if (t.text == "End") {
                if (Status s = expect("Site"); !s)
                    return s;
                BvhJoint& me = m_out.joints[static_cast<size_t>(index)];
                if (me.has_end_site)
                    return fail(t.line, "joint has two End Sites");
                if (Status s = expect("{"); !s)
                    return s;
                if (Status s = expect("OFFSET"); !s)
                    return s;
                glm::dvec3 v;
                if (Status s = vec3(v); !s)
                    return s;
                if (Status s = expect("}"); !s)
                    return s;
                me.has_end_site = true;
                me.end_site = v;
            } else {
                return fail(t.line, fmt::format("expected JOINT, End Site or '}}', found '{}'",
                                                clip(t.text)));
            }
        }
    }

    // The MOTION section is line-oriented: each frame on its own line.
    Expected<BvhMotion> motion(int motion_line) {
        std::string_view rest = m_text.substr(m_lex.pos());
        int line = m_lex.line();
        auto nextLine = [&](std::string_view& out) {
            // Returns false at end of text; skips nothing (blank lines are the caller's call).
            if (rest.empty())
                return false;
            const size_t nl = rest.find('\n');
            out = rest.substr(0, nl);
            rest = nl == std::string_view::npos ? std::string_view{} : rest.substr(nl + 1);
            ++line;
            if (!out.empty() && out.back() == '\r')
                out.remove_suffix(1);
            return true;
        };
        // The rest of the MOTION line itself must be empty.
        std::string_view l;
        nextLine(l);
        --line;  // the MOTION line was already counted by the lexer
        auto trim = [](std::string_view s) {
            while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
                s.remove_prefix(1);
            while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
                s.remove_suffix(1);
            return s;
        };
        if (!trim(l).empty())
            return fail(motion_line, "unexpected text after MOTION");
        auto header = [&](std::string_view key, double& value) -> Status {
            std::string_view h;
            do {
                if (!nextLine(h))
                    return fail(line, fmt::format("file ends before '{}'", key));
            } while (trim(h).empty());
            h = trim(h);
            if (h.substr(0, key.size()) != key)
                return fail(line, fmt::format("expected '{}', found '{}'", key, clip(h)));
            if (!parseNumber(trim(h.substr(key.size())), value))
                return fail(line, fmt::format("'{}' needs a number", key));
            return Status::success();
        };
        double frames = 0;
        double frame_time = 0;
        if (Status s = header("Frames:", frames); !s)
            return makeError(s.error());
        if (frames != std::floor(frames) || frames < 1 || frames > m_limits.max_frames)
            return fail(line, fmt::format("Frames: {} is not a whole number in [1, {}]", frames,
                                          m_limits.max_frames));
        const int frames_line = line;
        if (Status s = header("Frame Time:", frame_time); !s)
            return makeError(s.error());
        if (!(frame_time >= 1e-4 && frame_time <= 10.0))
            return fail(line, fmt::format("Frame Time: {} s outside [0.0001, 10]", frame_time));
        const int64_t total = static_cast<int64_t>(frames) * m_out.channel_count;
        if (total > m_limits.max_values)
            return fail(frames_line, fmt::format("{} frames × {} channels exceeds {} values",
                                                 frames, m_out.channel_count, m_limits.max_values));
        m_out.frame_count = static_cast<int>(frames);
        m_out.frame_time_s = frame_time;
        m_out.values.reserve(static_cast<size_t>(total));
        for (int f = 0; f < m_out.frame_count; ++f) {
            std::string_view row;
            if (!nextLine(row))
                return fail(line, fmt::format("truncated: Frames: says {}, file holds {}",
                                              m_out.frame_count, f));
            int n = 0;
            size_t i = 0;
            for (std::string_view token = nextToken(row, i); !token.empty();
                 token = nextToken(row, i)) {
                double v = 0;
                if (!parseNumber(token, v) || std::fabs(v) > m_limits.max_abs_value)
                    return fail(line, fmt::format("frame {}: value {} '{}' is not a number within "
                                                  "±{}",
                                                  f, n + 1, clip(token), m_limits.max_abs_value));
                if (n >= m_out.channel_count)
                    return fail(line, fmt::format("frame {}: more than the {} values the "
                                                  "hierarchy's CHANNELS declare",
                                                  f, m_out.channel_count));
                m_out.values.push_back(v);
                ++n;
            }
            if (n != m_out.channel_count)
                return fail(line, fmt::format("frame {}: {} values, the hierarchy's CHANNELS "
                                              "declare {}",
                                              f, n, m_out.channel_count));
        }
        // Exporters are known to write one frame more than Frames: declares (the Boxing_Toes
        // file of assimp-testmodels does): whole extra frames are checked and ignored, anything
        // else after the frames is an error.
        std::string_view tail;
        while (nextLine(tail)) {
            if (trim(tail).empty())
                continue;
            if (m_out.ignored_frames >= 16 || countNumbers(tail) != m_out.channel_count)
                return fail(line, fmt::format("data after the {} frames that Frames: declares",
                                              m_out.frame_count));
            ++m_out.ignored_frames;
        }
        return std::move(m_out);
    }

    HierarchyLexer m_lex;
    std::string_view m_text;
    std::string m_source;
    BvhLimits m_limits;
    BvhMotion m_out;
};

}  // namespace

int BvhMotion::findJoint(std::string_view name) const {
    for (size_t i = 0; i < joints.size(); ++i) {
        if (joints[i].name == name)
            return static_cast<int>(i);
    }
    return -1;
}

Expected<BvhMotion> parseBvh(std::string_view text, std::string_view source_name,
                             const BvhLimits& limits) {
    return Parser(text, source_name, limits).run();
}

Expected<BvhMotion> loadBvhFile(const std::string& path, const BvhLimits& limits) {
    auto text = readTextFile(path, limits.max_bytes);
    if (!text)
        return makeError(text.error());
    return parseBvh(*text, path, limits);
}

std::vector<BvhTransform> bvhWorldTransforms(const BvhMotion& m, int frame) {
    QVR_CHECK(frame >= -1 && frame < m.frame_count);
    std::vector<BvhTransform> world(m.joints.size());
    const double* values = frame >= 0 ? m.frame(frame) : nullptr;
    for (size_t i = 0; i < m.joints.size(); ++i) {
        const BvhJoint& j = m.joints[i];
        glm::dvec3 t = j.offset;
        glm::dquat r(1.0, 0.0, 0.0, 0.0);
        for (size_t c = 0; c < j.channels.size(); ++c) {
            const double v = values ? values[j.first_channel + static_cast<int>(c)] : 0.0;
            switch (j.channels[c]) {
                case BvhChannel::kXpos:
                    t.x += v;
                    break;
                case BvhChannel::kYpos:
                    t.y += v;
                    break;
                case BvhChannel::kZpos:
                    t.z += v;
                    break;
                // Channel order is the order of the matrix product: "Z X Y" is Rz·Rx·Ry.
                case BvhChannel::kXrot:
                    r = r * glm::angleAxis(v * kRadPerDeg, glm::dvec3(1, 0, 0));
                    break;
                case BvhChannel::kYrot:
                    r = r * glm::angleAxis(v * kRadPerDeg, glm::dvec3(0, 1, 0));
                    break;
                case BvhChannel::kZrot:
                    r = r * glm::angleAxis(v * kRadPerDeg, glm::dvec3(0, 0, 1));
                    break;
            }
        }
        if (j.parent < 0) {
            world[i] = {r, t};
        } else {
            const BvhTransform& p = world[static_cast<size_t>(j.parent)];
            world[i] = {glm::normalize(p.rotation * r), p.apply(t)};
        }
    }
    return world;
}

}  // namespace qvr
