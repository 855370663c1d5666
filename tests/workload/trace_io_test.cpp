// Workload trace files (docs/WORKLOAD_FORMAT.md), read as untrusted input (STYLE.md §6): a
// written trace reads back unchanged, and every kind of malformed file gives an error that
// names the line, never a crash.
#include "qvr/workload/trace_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "qvr/workload/synthetic.h"

namespace qvr {
namespace {

using ::testing::HasSubstr;

// A hand-made trace whose values exercise the format: odd doubles, zeros, a custom profile.
WorkloadTrace handMadeTrace(int frames = 3) {
    WorkloadTrace t;
    WorkloadHeader& h = t.header;
    h.name = "hand \"made\" \\ trace";
    h.source = "unit test, ünïcode ok";
    h.profile = lowResHmdProfile();
    h.profile.name = "custom";
    h.profile.fov_h_deg = 97.25;
    h.profile.fov_v_deg = 103.5;
    h.profile.refresh_hz = 72.0;
    h.profile.lens.k1 = 0.125;
    h.profile.lens.k2 = -0.0625;
    h.profile.lens.chroma_red_scale = 0.99;
    h.profile.lens.chroma_blue_scale = 1.01;
    h.profile.acuity.omega0_deg = 0.03;
    h.profile.acuity.slope = 0.021;
    h.ring_deg = 1.5;
    h.rings = 40;  // 60° of rings
    h.scales = {1.0, 2.0, 3.7, 8.0};
    h.batches = 777;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int n = 0; n < frames; ++n) {
        WorkloadFrame f;
        f.index = n;
        f.time_ms = 13.888888888888891 * n + 0.1;
        f.head.orientation = quatFromEulerDeg({10.0 * n, -3.3, 1.7});
        f.head.position_m = {0.1f * static_cast<float>(n), 1.7f, -0.3f};
        f.gaze = {-12.345678901234567 + n, 7.0 / 3.0};
        for (int k = 0; k < h.rings; ++k) {
            f.triangles_per_ring.push_back(k == 5 ? 0.0 : 1e5 * u(rng));
            f.pixels_per_ring.push_back(1e-7 + 3e4 * u(rng));
        }
        for (size_t s = 0; s < h.scales.size(); ++s)
            f.bits_per_pixel.push_back(0.3 * std::pow(h.scales[s], 0.7) + u(rng));
        f.static_split = {12345.5 * u(rng), 0.25 + 0.5 * u(rng), 1e5 * u(rng), 7e4};
        if (n == 1)
            f.fovea_fragments_per_px = 3.0 + u(rng);  // recorded by a run; the others not
        t.frames.push_back(f);
    }
    return t;
}

std::string writeTrace(const WorkloadTrace& t) {
    std::stringstream ss;
    WorkloadTraceWriter w(ss);
    w.writeHeader(t.header);
    for (const auto& f : t.frames)
        w.writeFrame(f);
    return ss.str();
}

Expected<WorkloadTrace> readText(const std::string& text) {
    std::stringstream ss(text);
    return readWorkloadTrace(ss, "t.jsonl");
}

std::vector<std::string> splitLines(const std::string& text) {
    std::vector<std::string> lines;
    std::stringstream ss(text);
    std::string line;
    while (std::getline(ss, line))
        lines.push_back(line);
    return lines;
}

std::string joinLines(const std::vector<std::string>& lines) {
    std::string out;
    for (const auto& l : lines)
        out += l + "\n";
    return out;
}

void expectSameTrace(const WorkloadTrace& a, const WorkloadTrace& b) {
    const WorkloadHeader& ha = a.header;
    const WorkloadHeader& hb = b.header;
    EXPECT_EQ(ha.name, hb.name);
    EXPECT_EQ(ha.source, hb.source);
    EXPECT_EQ(ha.profile.name, hb.profile.name);
    EXPECT_EQ(ha.profile.width_px, hb.profile.width_px);
    EXPECT_EQ(ha.profile.height_px, hb.profile.height_px);
    EXPECT_EQ(ha.profile.fov_h_deg, hb.profile.fov_h_deg);
    EXPECT_EQ(ha.profile.fov_v_deg, hb.profile.fov_v_deg);
    EXPECT_EQ(ha.profile.refresh_hz, hb.profile.refresh_hz);
    EXPECT_EQ(ha.profile.lens.k1, hb.profile.lens.k1);
    EXPECT_EQ(ha.profile.lens.k2, hb.profile.lens.k2);
    EXPECT_EQ(ha.profile.lens.chroma_red_scale, hb.profile.lens.chroma_red_scale);
    EXPECT_EQ(ha.profile.lens.chroma_blue_scale, hb.profile.lens.chroma_blue_scale);
    EXPECT_EQ(ha.profile.acuity.omega0_deg, hb.profile.acuity.omega0_deg);
    EXPECT_EQ(ha.profile.acuity.slope, hb.profile.acuity.slope);
    EXPECT_EQ(ha.ring_deg, hb.ring_deg);
    EXPECT_EQ(ha.rings, hb.rings);
    EXPECT_EQ(ha.scales, hb.scales);
    EXPECT_EQ(ha.batches, hb.batches);
    ASSERT_EQ(a.frames.size(), b.frames.size());
    for (size_t i = 0; i < a.frames.size(); ++i) {
        const WorkloadFrame& fa = a.frames[i];
        const WorkloadFrame& fb = b.frames[i];
        EXPECT_EQ(fa.index, fb.index);
        EXPECT_EQ(fa.time_ms, fb.time_ms);
        // Orientation is stored as float and renormalised on reading.
        EXPECT_NEAR(fa.head.orientation.w, fb.head.orientation.w, 1e-6f);
        EXPECT_NEAR(fa.head.orientation.x, fb.head.orientation.x, 1e-6f);
        EXPECT_NEAR(fa.head.orientation.y, fb.head.orientation.y, 1e-6f);
        EXPECT_NEAR(fa.head.orientation.z, fb.head.orientation.z, 1e-6f);
        EXPECT_EQ(fa.head.position_m, fb.head.position_m);
        EXPECT_EQ(fa.gaze.x_deg, fb.gaze.x_deg);
        EXPECT_EQ(fa.gaze.y_deg, fb.gaze.y_deg);
        EXPECT_EQ(fa.triangles_per_ring, fb.triangles_per_ring);
        EXPECT_EQ(fa.pixels_per_ring, fb.pixels_per_ring);
        EXPECT_EQ(fa.bits_per_pixel, fb.bits_per_pixel);
        EXPECT_EQ(fa.static_split.fg_triangles, fb.static_split.fg_triangles);
        EXPECT_EQ(fa.static_split.fg_screen_fraction, fb.static_split.fg_screen_fraction);
        EXPECT_EQ(fa.static_split.bg_bytes, fb.static_split.bg_bytes);
        EXPECT_EQ(fa.static_split.depth_bytes, fb.static_split.depth_bytes);
        EXPECT_EQ(fa.bits_per_pixel_lossless, fb.bits_per_pixel_lossless);
        EXPECT_EQ(fa.fovea_fragments_per_px, fb.fovea_fragments_per_px);
        EXPECT_EQ(fa.static_split.bg_bytes_lossless, fb.static_split.bg_bytes_lossless);
    }
}

TEST(WorkloadTrace, PreservesEverythingWhenWrittenAndRead) {
    const WorkloadTrace t = handMadeTrace();
    ASSERT_TRUE(validateTrace(t).ok()) << validateTrace(t).error();
    const std::string text = writeTrace(t);
    // One header line and one line per frame.
    EXPECT_EQ(splitLines(text).size(), t.frames.size() + 1);
    auto back = readText(text);
    ASSERT_TRUE(back.ok()) << back.error();
    expectSameTrace(t, *back);
    // Writing what was read gives the same lines, except the quaternions, which the reader
    // renormalises (a last-bit change in float).
    const auto again = splitLines(writeTrace(*back));
    const auto first = splitLines(text);
    ASSERT_EQ(again.size(), first.size());
    EXPECT_TRUE(again[0] == first[0]);
    auto strip_q = [](const std::string& l) {
        const auto at = l.find("\"q\":[");
        return at == std::string::npos ? l : l.substr(0, at) + l.substr(l.find(']', at));
    };
    for (size_t i = 1; i < first.size(); ++i)
        EXPECT_TRUE(strip_q(again[i]) == strip_q(first[i])) << "line " << i + 1;
}

TEST(WorkloadTrace, PreservesSyntheticTraceWhenSavedToFile) {
    SyntheticSpec spec = defaultSyntheticSpec();
    spec.frames = 12;
    const WorkloadTrace t = generateSyntheticWorkload(spec);
    const auto path = std::filesystem::temp_directory_path() /
                      ("qvr_workload_trace_test_" + std::to_string(::getpid()) + ".jsonl");
    ASSERT_TRUE(saveWorkloadTrace(t, path.string()).ok());
    auto back = loadWorkloadTrace(path.string());
    ASSERT_TRUE(back.ok()) << back.error();
    expectSameTrace(t, *back);
    std::filesystem::remove(path);
}

TEST(WorkloadTrace, ReadsWhenLinesEndInCrlfOrBlankLinesOrNoFinalNewline) {
    auto lines = splitLines(writeTrace(handMadeTrace()));
    std::string crlf;
    for (const auto& l : lines)
        crlf += l + "\r\n";
    auto a = readText(crlf);
    ASSERT_TRUE(a.ok()) << a.error();
    EXPECT_EQ(a->frames.size(), 3u);
    auto b =
        readText("\n  \n" + lines[0] + "\n\n" + lines[1] + "\n\t\n" + lines[2] + "\n" + lines[3]);
    ASSERT_TRUE(b.ok()) << b.error();
    EXPECT_EQ(b->frames.size(), 3u);
}

TEST(SaveWorkloadTrace, FailsWhenTraceIsInvalidOrPathUnwritable) {
    WorkloadTrace t = handMadeTrace();
    EXPECT_FALSE(saveWorkloadTrace(t, "/nonexistent/dir/x.jsonl").ok());
    t.frames[1].time_ms = -5.0;
    const auto path = std::filesystem::temp_directory_path() /
                      ("qvr_never_written_" + std::to_string(::getpid()) + ".jsonl");
    EXPECT_FALSE(saveWorkloadTrace(t, path.string()).ok());
    // An invalid trace is refused before the file is created.
    EXPECT_FALSE(std::filesystem::exists(path));
}

// Checks that text is rejected with an error naming line `line` (1-based) and mentioning `what`.
void expectErrorAtLine(const std::string& text, int line, const std::string& what) {
    auto r = readText(text);
    ASSERT_FALSE(r.ok()) << "accepted; expected an error at line " << line << " about " << what;
    EXPECT_THAT(r.error(), HasSubstr("t.jsonl:" + std::to_string(line) + ":")) << r.error();
    EXPECT_THAT(r.error(), HasSubstr(what)) << r.error();
}

// The valid trace's lines, to break one at a time.
std::vector<std::string> validLines() {
    return splitLines(writeTrace(handMadeTrace()));
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << "'" << from << "' not in the line";
    if (at != std::string::npos)
        s.replace(at, from.size(), to);
    return s;
}

TEST(ReadWorkloadTrace, FailsWhenInputIsEmptyOrHeaderOnly) {
    auto empty = readText("");
    ASSERT_FALSE(empty.ok());
    EXPECT_THAT(empty.error(), HasSubstr("t.jsonl"));
    EXPECT_THAT(empty.error(), HasSubstr("header"));
    auto blank = readText("\n\n   \n");
    ASSERT_FALSE(blank.ok());
    auto header_only = readText(validLines()[0] + "\n");
    ASSERT_FALSE(header_only.ok());
    EXPECT_THAT(header_only.error(), HasSubstr("t.jsonl"));
    EXPECT_THAT(header_only.error(), HasSubstr("no frames"));
}

TEST(ReadWorkloadTrace, NamesLineWhenLineIsNotJsonObject) {
    auto lines = validLines();
    auto l = lines;
    l[2] = "this is not json";
    expectErrorAtLine(joinLines(l), 3, "JSON");
    l = lines;
    l[0] = "[1, 2, 3]";
    expectErrorAtLine(joinLines(l), 1, "object");
    l = lines;
    l[1] = "[{\"i\": 0}]";
    expectErrorAtLine(joinLines(l), 2, "object");
    l = lines;
    l[3] = "42";
    expectErrorAtLine(joinLines(l), 4, "object");
    l = lines;
    l[1] = lines[1].substr(0, lines[1].size() / 2);  // truncated mid-record
    expectErrorAtLine(joinLines(l), 2, "JSON");
    l = lines;
    l[2] = std::string("{\"i\":\0\x01\xff}", 10);
    expectErrorAtLine(joinLines(l), 3, "");
}

TEST(ReadWorkloadTrace, NamesLineWhenHeaderFormatOrVersionIsWrong) {
    const auto lines = validLines();
    auto l = lines;
    l[0] = replaced(l[0], "\"qvr-workload\"", "\"qvr-workloads\"");
    expectErrorAtLine(joinLines(l), 1, "format");
    l = lines;
    l[0] = replaced(l[0], "\"format\":\"qvr-workload\",", "");
    expectErrorAtLine(joinLines(l), 1, "format");
    l = lines;
    l[0] = replaced(l[0], "\"version\":1", "\"version\":2");
    expectErrorAtLine(joinLines(l), 1, "version");
    l = lines;
    l[0] = replaced(l[0], "\"version\":1", "\"version\":\"1\"");
    expectErrorAtLine(joinLines(l), 1, "version");
    l = lines;
    l[0] = replaced(l[0], "\"version\":1", "\"version\":1.5");
    expectErrorAtLine(joinLines(l), 1, "version");
    // A frame where the header belongs.
    l = lines;
    l.erase(l.begin());
    expectErrorAtLine(joinLines(l), 1, "format");
}

TEST(ReadWorkloadTrace, NamesLineAndFieldWhenFieldIsMissing) {
    const auto lines = validLines();
    struct Case {
        int line;  // 0-based index into lines
        std::string from, to, field;
    };
    const Case cases[] = {
        {0, "\"rings\":40,", "", "rings"},
        {0, "\"ring_deg\":1.5,", "", "ring_deg"},
        {0, "\"scales\":[1.0,2.0,3.7,8.0],", "", "scales"},
        {0, "\"width_px\":1280", "\"widthpx\":1280", "width_px"},
        {0, "\"profile\":", "\"profiles\":", "profile"},
        {1, "\"i\":0,", "", "'i'"},
        {1, "\"t_ms\":0.1,", "", "t_ms"},
        {2, "\"tri\":", "\"tris\":", "tri"},
        {2, "\"pix\":", "\"pixels\":", "pix"},
        {2, "\"bpp\":", "\"bits\":", "bpp"},
        {3, "\"gaze\":", "\"gaz\":", "gaze"},
        {3, "\"head\":", "\"hea\":", "head"},
        {3, "\"q\":", "\"quat\":", "'q'"},
        {3, "\"static\":", "\"statics\":", "static"},
        {3, "\"fg_frac\":", "\"fg_fraction\":", "fg_frac"},
    };
    for (const Case& c : cases) {
        auto l = lines;
        l[static_cast<size_t>(c.line)] = replaced(l[static_cast<size_t>(c.line)], c.from, c.to);
        SCOPED_TRACE(c.from);
        expectErrorAtLine(joinLines(l), c.line + 1, c.field);
    }
}

TEST(ReadWorkloadTrace, NamesLineWhenArrayHasWrongLengthOrType) {
    const auto lines = validLines();
    auto l = lines;
    // One ring short: drop the first element of "tri".
    {
        const auto at = l[1].find("\"tri\":[") + 7;
        const auto comma = l[1].find(',', at);
        l[1].erase(at, comma - at + 1);
    }
    expectErrorAtLine(joinLines(l), 2, "tri");
    l = lines;
    {
        const auto at = l[2].find("\"pix\":[") + 7;
        l[2].insert(at, "1.0,");
    }
    expectErrorAtLine(joinLines(l), 3, "pix");
    l = lines;
    {
        const auto at = l[3].find("\"bpp\":[") + 7;
        l[3].insert(at, "1.0,");
    }
    expectErrorAtLine(joinLines(l), 4, "bpp");
    l = lines;
    {
        const auto at = l[1].find("\"gaze\":[") + 8;
        l[1].insert(at, "0.0,");
    }
    expectErrorAtLine(joinLines(l), 2, "gaze");
    l = lines;
    {
        const auto at = l[1].find("\"q\":[") + 5;
        const auto comma = l[1].find(',', at);
        l[1].erase(at, comma - at + 1);
    }
    expectErrorAtLine(joinLines(l), 2, "'q'");
    l = lines;
    l[2] = replaced(l[2], "\"tri\":[", "\"tri\":[\"many\",");
    {
        // Keep the length right: drop the last element.
        const auto end = l[2].find(']', l[2].find("\"tri\":["));
        const auto comma = l[2].rfind(',', end);
        l[2].erase(comma, end - comma);
    }
    expectErrorAtLine(joinLines(l), 3, "tri");
    l = lines;
    l[3] = replaced(l[3], "\"gaze\":[", "\"gaze\":[null,");
    {
        const auto end = l[3].find(']', l[3].find("\"gaze\":["));
        const auto comma = l[3].rfind(',', end);
        l[3].erase(comma, end - comma);
    }
    expectErrorAtLine(joinLines(l), 4, "gaze");
    l = lines;
    l[1] = replaced(l[1], "\"tri\":[", "\"tri\":{\"a\":1},\"x\":[");
    expectErrorAtLine(joinLines(l), 2, "tri");
    l = lines;
    l[0] = replaced(l[0], "\"scales\":[1.0,2.0,3.7,8.0]", "\"scales\":\"1,2,4\"");
    expectErrorAtLine(joinLines(l), 1, "scales");
    l = lines;
    l[1] = replaced(l[1], "\"t_ms\":0.1", "\"t_ms\":\"0.1\"");
    expectErrorAtLine(joinLines(l), 2, "t_ms");
}

TEST(ReadWorkloadTrace, NamesLineWhenHeaderValueIsOutOfRange) {
    const auto lines = validLines();
    struct Case {
        std::string from, to, field;
    };
    const Case cases[] = {
        {"\"rings\":40", "\"rings\":513", "rings"},  // beyond kMaxRings
        {"\"rings\":40", "\"rings\":100000000000", "rings"},
        {"\"rings\":40", "\"rings\":-3", "rings"},
        {"\"ring_deg\":1.5", "\"ring_deg\":-1.5", "ring_deg"},
        {"\"width_px\":1280", "\"width_px\":0", "width_px"},
        {"\"fov_h_deg\":97.25", "\"fov_h_deg\":-97.25", "fov_h_deg"},
        {"\"refresh_hz\":72.0", "\"refresh_hz\":5000", "refresh_hz"},
        {"\"refresh_hz\":72.0", "\"refresh_hz\":-1e308", "refresh_hz"},
        {"\"batches\":777", "\"batches\":-1", "batches"},
        {"\"k1\":0.125", "\"k1\":100", "k1"},
        {"\"slope\":0.021", "\"slope\":\"steep\"", "slope"},
    };
    for (const Case& c : cases) {
        auto l = lines;
        l[0] = replaced(l[0], c.from, c.to);
        SCOPED_TRACE(c.to);
        auto r = readText(joinLines(l));
        ASSERT_FALSE(r.ok());
        EXPECT_THAT(r.error(), HasSubstr(c.field)) << r.error();
        EXPECT_THAT(r.error(), HasSubstr("t.jsonl:1:")) << r.error();
    }
    // More scales than kMaxScales.
    auto l = lines;
    std::string many = "\"scales\":[";
    for (int i = 1; i <= kMaxScales + 1; ++i)
        many += std::to_string(i) + (i <= kMaxScales ? "," : "]");
    l[0] = replaced(l[0], "\"scales\":[1.0,2.0,3.7,8.0]", many);
    expectErrorAtLine(joinLines(l), 1, "scales");
}

TEST(ReadWorkloadTrace, NamesLineWhenFrameValueIsOutOfRange) {
    const auto lines = validLines();
    auto l = lines;
    l[2] = replaced(l[2], "\"depth_bytes\":70000.0", "\"depth_bytes\":-70000.0");
    expectErrorAtLine(joinLines(l), 3, "depth_bytes");
    l = lines;
    l[2] = replaced(l[2], "\"fg_frac\":", "\"fg_frac\":1.5,\"was\":");
    expectErrorAtLine(joinLines(l), 3, "fg_frac");
    l = lines;
    l[1] = replaced(l[1], "\"i\":0", "\"i\":-1");
    expectErrorAtLine(joinLines(l), 2, "'i'");
    // The optional fragments per fovea pixel: a number in [0, 1000].
    for (const char* bad : {"-0.5", "1e4", "\"many\"", "null"}) {
        l = lines;
        l[2] = replaced(l[2], "\"static\":", std::string("\"frag_px\":") + bad + ",\"static\":");
        expectErrorAtLine(joinLines(l), 3, "frag_px");
    }
}

TEST(ReadWorkloadTrace, NamesLineWhenQuaternionIsNotUnit) {
    auto l = validLines();
    const auto at = l[2].find("\"q\":[") + 5;
    const auto end = l[2].find(']', at);
    l[2].replace(at, end - at, "5.0,0.0,0.0,0.0");
    expectErrorAtLine(joinLines(l), 3, "norm");
    l[2].replace(at, l[2].find(']', at) - at, "0.0,0.0,0.0,0.0");
    expectErrorAtLine(joinLines(l), 3, "norm");
}

TEST(ReadWorkloadTrace, NamesLineWhenLineExceedsFourMebibytes) {
    auto l = validLines();
    // A syntactically valid frame line padded past 4 MiB with spaces.
    l[2].insert(1, (size_t{4} << 20) + 10, ' ');
    expectErrorAtLine(joinLines(l), 3, "longer");
    // Just under the limit it is read normally.
    auto ok = validLines();
    ok[2].insert(1, (size_t{4} << 20) - ok[2].size() - 1, ' ');
    auto r = readText(joinLines(ok));
    EXPECT_TRUE(r.ok()) << r.error();
}

TEST(ReadWorkloadTrace, RejectsNegativeRingValuesAndBackwardTimeWhenValidating) {
    // These pass the field parser and are caught by the per-frame validation; the message names the
    // line.
    auto lines = validLines();
    auto l = lines;
    l[2] = replaced(l[2], "\"tri\":[", "\"tri\":[-1.0,");
    {
        const auto end = l[2].find(']', l[2].find("\"tri\":["));
        const auto comma = l[2].rfind(',', end);
        l[2].erase(comma, end - comma);
    }
    auto neg = readText(joinLines(l));
    ASSERT_FALSE(neg.ok());
    EXPECT_THAT(neg.error(), HasSubstr(":3:"));  // the line, not only the frame
    EXPECT_THAT(neg.error(), HasSubstr("non-negative"));
    l = lines;
    l[3] = replaced(l[3], "\"t_ms\":", "\"t_ms\":0.05,\"t_old\":");
    auto back = readText(joinLines(l));
    ASSERT_FALSE(back.ok());
    EXPECT_THAT(back.error(), HasSubstr(":4:"));
    EXPECT_THAT(back.error(), HasSubstr("time_ms"));
}

// Negative ring values and time going backwards name the line, like every other
// malformed-trace error (found by this suite; fixed).
TEST(ReadWorkloadTrace, NamesLineWhenRingValueIsNegativeOrTimeGoesBackwards) {
    auto lines = validLines();
    auto l = lines;
    l[2] = replaced(l[2], "\"pix\":[", "\"pix\":[-1.0,");
    {
        const auto end = l[2].find(']', l[2].find("\"pix\":["));
        const auto comma = l[2].rfind(',', end);
        l[2].erase(comma, end - comma);
    }
    expectErrorAtLine(joinLines(l), 3, "pix");
    l = lines;
    l[3] = replaced(l[3], "\"t_ms\":", "\"t_ms\":0.05,\"t_old\":");
    expectErrorAtLine(joinLines(l), 4, "t_ms");
}

TEST(ReadWorkloadTrace, NeverCrashesWhenBytesAreMutated) {
    // A small fuzz loop: flip, insert and delete bytes of a valid trace; every outcome must be
    // a value that validates or an error with a message.
    const std::string valid = writeTrace(handMadeTrace(2));
    std::mt19937_64 rng(2024);
    std::uniform_int_distribution<size_t> pos(0, valid.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    const char interesting[] = "{}[],:\"-e.0123456789\n\\ nultrfa";
    std::uniform_int_distribution<size_t> pick(0, sizeof interesting - 2);
    int rejected = 0;
    for (int i = 0; i < 1500; ++i) {
        std::string t = valid;
        const int edits = 1 + i % 4;
        for (int e = 0; e < edits; ++e) {
            const size_t p = pos(rng) % t.size();
            switch ((i + e) % 4) {
                case 0:
                    t[p] = static_cast<char>(byte(rng));
                    break;
                case 1:
                    t[p] = interesting[pick(rng)];
                    break;
                case 2:
                    t.insert(p, 1, interesting[pick(rng)]);
                    break;
                default:
                    t.erase(p, 1 + p % 7);
                    break;
            }
        }
        auto r = readText(t);
        if (r.ok()) {
            EXPECT_TRUE(validateTrace(*r).ok());
        } else {
            EXPECT_FALSE(r.error().empty());
            ++rejected;
        }
    }
    EXPECT_GT(rejected, 1000);
}

TEST(LoadWorkloadTrace, NamesPathWhenFileIsMissing) {
    auto r = loadWorkloadTrace("/nonexistent/qvr/trace.jsonl");
    ASSERT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("/nonexistent/qvr/trace.jsonl"));
}

// The paper's codec setting (lossless, §2.3) recorded beside ours: it reads back, replaces the
// streaming bytes only when asked, and a trace without it or with a malformed one is an error.
TEST(WorkloadCodecModel, ReadsLosslessBytesAndAppliesThemOnlyWhenAsked) {
    WorkloadTrace t = handMadeTrace();
    EXPECT_FALSE(hasLosslessCodec(t));
    for (auto& f : t.frames) {
        for (double b : f.bits_per_pixel)
            f.bits_per_pixel_lossless.push_back(40.0 * b);
        f.static_split.bg_bytes_lossless = 1.5e6;
    }
    auto back = readText(writeTrace(t));
    ASSERT_TRUE(back) << back.error();
    expectSameTrace(t, *back);
    ASSERT_TRUE(hasLosslessCodec(*back));
    WorkloadTrace stream = *back;
    ASSERT_TRUE(applyCodecModel(stream, CodecModel::kStream));
    EXPECT_EQ(stream.frames[1].bits_per_pixel, t.frames[1].bits_per_pixel);
    ASSERT_TRUE(applyCodecModel(*back, CodecModel::kLossless));
    EXPECT_EQ(back->frames[1].bits_per_pixel, t.frames[1].bits_per_pixel_lossless);
    EXPECT_EQ(back->frames[2].static_split.bg_bytes, 1.5e6);
    EXPECT_EQ(back->frames[2].static_split.depth_bytes, t.frames[2].static_split.depth_bytes);
}

TEST(WorkloadCodecModel, FailsWhenLosslessIsMissingMalformedOrUnknown) {
    WorkloadTrace t = handMadeTrace();
    const Status missing = applyCodecModel(t, CodecModel::kLossless);
    ASSERT_FALSE(missing);
    EXPECT_THAT(missing.error(), HasSubstr("no lossless"));
    EXPECT_FALSE(parseCodecModel("h265"));
    EXPECT_EQ(*parseCodecModel("lossless"), CodecModel::kLossless);
    EXPECT_EQ(*parseCodecModel("stream"), CodecModel::kStream);

    auto lines = validLines();
    const auto at = lines[2].find("\"bpp\":[");
    lines[2].insert(at, "\"bpp_lossless\":[1,2],");
    expectErrorAtLine(joinLines(lines), 3, "bpp_lossless");
    lines = validLines();
    const auto st = lines[1].find("\"static\":{") + 10;
    lines[1].insert(st, "\"bg_bytes_lossless\":-5,");
    expectErrorAtLine(joinLines(lines), 2, "bg_bytes_lossless");
}

}  // namespace
}  // namespace qvr
