// ProcessRunner with /bin/sh one-liners: exit statuses, the result file, and a signal to the
// sheet passed to the child under way.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "qvr/experiment/validation.h"

namespace qvr::experiment {
namespace {

TEST(ProcessRunner, ReadsTheResultOfAChildThatExitedZero) {
    const std::string path = testing::TempDir() + "/qvr_runner_result.json";
    ProcessRunner runner;
    const ChildOutcome done = runner.run({"printf '{\"a\": 1}' > '" + path + "'", "", "", path});
    EXPECT_EQ(done.exit_code, 0);
    EXPECT_EQ(done.result.value("a", 0), 1);
    const ChildOutcome failed = runner.run({"sh -c 'exit 3'", "", "", path});
    EXPECT_EQ(failed.exit_code, 3);
    EXPECT_TRUE(failed.result.is_null());  // not read after a failure
    EXPECT_EQ(runner.stopSignal(), 0);
    std::filesystem::remove(path);
}

TEST(ProcessRunner, AKilledChildExitsWith128PlusItsSignal) {
    ProcessRunner runner;
    EXPECT_EQ(runner.run({"kill -KILL $$", "", "", ""}).exit_code, 128 + 9);
    EXPECT_EQ(runner.stopSignal(), 0);
}

TEST(ProcessRunner, ASignalToTheSheetStopsTheChildUnderWay) {
    ProcessRunner runner;
    // The child signals its parent, which passes the signal back to it.
    const ChildOutcome o = runner.run({"sh -c 'kill -INT $PPID; exec sleep 20'", "", "", ""});
    EXPECT_EQ(runner.stopSignal(), 2);
    EXPECT_EQ(o.exit_code, 128 + 2);
}

}  // namespace
}  // namespace qvr::experiment
