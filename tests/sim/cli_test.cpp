// `qvr sim` and `qvr eval` on bad input: a clear message on stderr and exit status 2; on good
// input, summary.json with the documented fields. Runs the qvr binary built next to this test.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "qvr/sim/benches.h"
#include "qvr/workload/trace_io.h"

namespace {

namespace fs = std::filesystem;

fs::path qvrBinary() {
    std::array<char, 4096> buf{};
    const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
    if (n <= 0)
        return {};
    // build/<dir>/tests/sim_tests → build/<dir>/apps/qvr/qvr
    return fs::path(std::string(buf.data(), static_cast<size_t>(n))).parent_path().parent_path() /
           "apps" / "qvr" / "qvr";
}

struct Outcome {
    int status = -1;
    std::string err;
};

Outcome run(const std::string& args) {
    const fs::path tmp = fs::temp_directory_path() / ("qvr_cli_" + std::to_string(getpid()));
    fs::create_directories(tmp);
    const fs::path err_file = tmp / "stderr.txt";
    const std::string cmd =
        qvrBinary().string() + " " + args + " >/dev/null 2>" + err_file.string();
    const int raw = std::system(cmd.c_str());
    Outcome o;
    o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    {
        std::ifstream in(err_file);
        std::stringstream ss;
        ss << in.rdbuf();
        o.err = ss.str();
    }
    std::error_code ec;
    fs::remove_all(tmp, ec);  // nothing of a test left in the temporary directory
    return o;
}

class Cli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(qvrBinary()))
            GTEST_SKIP() << "qvr binary not built at " << qvrBinary();
        m_out = fs::temp_directory_path() / ("qvr_cli_out_" + std::to_string(getpid()));
    }
    void TearDown() override { fs::remove_all(m_out); }
    fs::path m_out;
};

TEST_F(Cli, SimRejectsBadInputWithStatusTwoAndAMessage) {
    const std::string out = " --out " + m_out.string();
    struct Case {
        std::string args;
        std::string needle;
    };
    const fs::path bad_trace = fs::temp_directory_path() / "qvr_cli_bad.down";
    {
        std::ofstream f(bad_trace);
        f << "0\n5\nthree\n";
    }
    const std::vector<Case> cases = {
        {"sim --bench nope --design qvr" + out, "unknown bench"},
        {"sim --bench doom3-h --design turbo" + out, "unknown design"},
        {"sim --bench doom3-h --net carrier-pigeon" + out, "unknown network"},
        {"sim --bench doom3-h --net trace:" + bad_trace.string() + out, "expected a non-negative"},
        {"sim --bench doom3-h --net trace:/nonexistent.down" + out, "cannot open"},
        {"sim --bench doom3-h --gpu-mhz -5" + out, "--gpu-mhz"},
        {"sim --bench doom3-h --gpu-mhz abc" + out, ""},
        {"sim --bench doom3-h --frames 0" + out, "--frames"},
        {"sim --design qvr" + out, "exactly one"},
        {"sim --bench doom3-h --trace /nonexistent.jsonl" + out, "exactly one"},
        {"sim --trace /nonexistent.jsonl" + out, "nonexistent"},
        {"eval --frames 5" + out, "--frames"},
        {"eval --jobs 0" + out, "--jobs"},
        {"eval --bench doom9" + out, "unknown bench"},
        {"eval --frames 30 --mahimahi " + bad_trace.string() + out, "expected a non-negative"},
        {"eval --codec-model h265" + out, "codec model"},
        {"sim --bench doom3-h --codec-model lossy" + out, "codec model"},
    };
    for (const Case& c : cases) {
        const Outcome o = run(c.args);
        EXPECT_EQ(o.status, 2) << c.args << "\n" << o.err;
        EXPECT_FALSE(o.err.empty()) << c.args;
        if (!c.needle.empty()) {
            EXPECT_NE(o.err.find(c.needle), std::string::npos) << o.err;
        }
    }
    fs::remove(bad_trace);
}

TEST_F(Cli, SimWritesSummaryWithTheDocumentedFields) {
    const Outcome o =
        run("sim --bench doom3-l --design qvr --gpu-mhz 400 --net lte --frames 40 "
            "--out " +
            m_out.string());
    ASSERT_EQ(o.status, 0) << o.err;
    std::ifstream in(m_out / "summary.json");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string j = ss.str();
    for (const char* field :
         {"\"runs\"", "\"bench\"", "\"design\"", "\"gpu_mhz\"", "\"net\"", "\"frames\"",
          "\"mtp_ms_mean\"", "\"fps_mean\"", "\"bytes_per_frame_mean\"",
          "\"pixels_per_frame_mean\"", "\"energy_mj_per_frame\"", "\"e1_deg_mean\"",
          "\"latency_ratio_final\""})
        EXPECT_NE(j.find(field), std::string::npos) << field;
    EXPECT_TRUE(fs::exists(m_out / "frames.csv"));
}

TEST_F(Cli, SimReplaysARecordedTraceFileAndRejectsAMalformedOne) {
    const fs::path good = fs::temp_directory_path() / ("qvr_cli_trace_" + std::to_string(getpid()));
    auto trace = qvr::makeSuiteBench("hl2-l", 25);
    ASSERT_TRUE(trace.ok());
    ASSERT_TRUE(qvr::saveWorkloadTrace(*trace, good.string()).ok());
    const Outcome ok =
        run("sim --trace " + good.string() + " --design dfr --frames 25 --out " + m_out.string());
    EXPECT_EQ(ok.status, 0) << ok.err;
    EXPECT_TRUE(fs::exists(m_out / "frames.csv"));
    // The synthetic trace has no lossless measurements: asking for them is bad input.
    const Outcome no_lossless = run("sim --trace " + good.string() +
                                    " --codec-model lossless --frames 25 --out " + m_out.string());
    EXPECT_EQ(no_lossless.status, 2);
    EXPECT_NE(no_lossless.err.find("no lossless"), std::string::npos) << no_lossless.err;
    {
        std::ofstream f(good);
        f << "{\"not\": \"a trace header\"}\n";
    }
    const Outcome bad = run("sim --trace " + good.string() + " --out " + m_out.string());
    EXPECT_EQ(bad.status, 2);
    EXPECT_FALSE(bad.err.empty());
    fs::remove(good);
}

}  // namespace
