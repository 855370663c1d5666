// ServerProcess (server_process.h): `qvr run`'s server child, exercised with /bin/sh children so
// no qvr binary is needed — the ready line parsed after other output, SIGTERM then SIGKILL on
// stop(), and the errors for a child that exits, stays silent, prints a malformed ready line or
// cannot be started.
#include "qvr/runtime/server_process.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace qvr::runtime {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Runs `script` under /bin/sh -c.
Expected<ServerProcess> startShell(const std::string& script, int ready_timeout_ms = 5000) {
    return ServerProcess::start("/bin/sh", {"-c", script}, ready_timeout_ms);
}

bool alive(pid_t pid) {
    return ::kill(pid, 0) == 0;
}

int64_t msSince(Clock::time_point t0) {
    return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0).count();
}

// A scratch directory per test, for the pid a child writes before it fails.
struct Scratch {
    std::filesystem::path dir;
    Scratch() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir = std::filesystem::temp_directory_path() /
              ("qvr_server_process_" + std::to_string(::getpid()) + "_" + info->name());
        std::filesystem::create_directories(dir);
    }
    ~Scratch() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
    std::string path(const std::string& name) const { return (dir / name).string(); }
};

pid_t readPid(const std::string& path) {
    std::ifstream in(path);
    long pid = -1;
    in >> pid;
    return static_cast<pid_t>(pid);
}

TEST(ServerProcess, ParsesThePortWhenTheReadyLineFollowsOtherOutput) {
    // The child exits 7 on SIGTERM (after its current 50 ms sleep): stop() returns that status.
    auto sp = startShell(
        "trap 'exit 7' TERM; echo 'qvr server: loading scene'; echo 'listening soon'; "
        "echo 'qvr server: listening on 127.0.0.1:45678 (psk, 4 streams)'; "
        "while :; do sleep 0.05; done");
    ASSERT_TRUE(sp.ok()) << sp.error();
    EXPECT_EQ(sp->port(), 45678);
    const pid_t pid = sp->pid();
    ASSERT_GT(pid, 0);
    EXPECT_TRUE(alive(pid));
    EXPECT_EQ(sp->stop(), 7);
    errno = 0;
    EXPECT_EQ(::kill(pid, 0), -1);
    const int err = errno;
    EXPECT_EQ(err, ESRCH);      // reaped: not even a zombie is left
    EXPECT_EQ(sp->stop(), -1);  // nothing left to stop
}

TEST(ServerProcess, TakesThePortAfterTheLastColonOfAnIpv6Address) {
    auto sp = startShell("echo 'qvr server: listening on [::1]:5001'; exec sleep 30");
    ASSERT_TRUE(sp.ok()) << sp.error();
    EXPECT_EQ(sp->port(), 5001);
    const pid_t pid = sp->pid();
    // A child that does not handle SIGTERM dies of it: 128 + 15.
    EXPECT_EQ(sp->stop(), 128 + SIGTERM);
    EXPECT_FALSE(alive(pid));
}

TEST(ServerProcess, KillsAChildThatIgnoresSigtermAfterTheGracePeriod) {
    auto sp = startShell(
        "trap '' TERM; echo 'qvr server: listening on 127.0.0.1:40000'; "
        "while :; do sleep 0.05; done");
    ASSERT_TRUE(sp.ok()) << sp.error();
    const pid_t pid = sp->pid();
    const auto t0 = Clock::now();
    EXPECT_EQ(sp->stop(300), 128 + SIGKILL);
    const int64_t ms = msSince(t0);
    EXPECT_GE(ms, 300);  // it had its grace period
    EXPECT_LT(ms, 3000);
    EXPECT_FALSE(alive(pid));
}

TEST(ServerProcess, ErrorsWhenTheChildExitsBeforeItIsReady) {
    const auto t0 = Clock::now();
    auto sp = startShell("echo 'qvr server: cannot load the scene'; exit 3");
    ASSERT_FALSE(sp.ok());
    EXPECT_NE(sp.error().find("exited before it was ready"), std::string::npos) << sp.error();
    EXPECT_NE(sp.error().find("status 3"), std::string::npos) << sp.error();
    EXPECT_LT(msSince(t0), 3000);  // noticed at its exit, not at the 5 s timeout
}

TEST(ServerProcess, ErrorsAfterTheTimeoutWhenTheChildStaysSilent) {
    const Scratch s;
    const auto t0 = Clock::now();
    auto sp = startShell("echo $$ > " + s.path("pid") + "; exec sleep 30", 300);
    const int64_t ms = msSince(t0);
    ASSERT_FALSE(sp.ok());
    EXPECT_NE(sp.error().find("not ready after 300 ms"), std::string::npos) << sp.error();
    EXPECT_GE(ms, 300);
    EXPECT_LT(ms, 3000);
    // The silent child was not left behind.
    const pid_t pid = readPid(s.path("pid"));
    ASSERT_GT(pid, 0);
    EXPECT_FALSE(alive(pid));
}

TEST(ServerProcess, ErrorsOnAMalformedReadyLineAndStopsTheChild) {
    for (const std::string addr :
         {"127.0.0.1:0", "127.0.0.1:99999", "127.0.0.1:http", "127.0.0.1:-5", "localhost", ""}) {
        const Scratch s;
        auto sp = startShell("echo $$ > " + s.path("pid") + "; echo 'qvr server: listening on " +
                             addr + "'; exec sleep 30");
        ASSERT_FALSE(sp.ok()) << "'" << addr << "' gave port " << sp->port();
        EXPECT_NE(sp.error().find("unreadable ready line"), std::string::npos) << sp.error();
        const pid_t pid = readPid(s.path("pid"));
        ASSERT_GT(pid, 0);
        EXPECT_FALSE(alive(pid)) << addr;
    }
}

TEST(ServerProcess, ErrorsWithoutCrashingWhenTheExecutableDoesNotExist) {
    const std::string missing = "/nonexistent/qvr-" + std::to_string(::getpid());
    auto sp = ServerProcess::start(missing, {"server"}, 2000);
    ASSERT_FALSE(sp.ok());
    EXPECT_NE(sp.error().find(missing), std::string::npos) << sp.error();
    // A file that exists but cannot be executed.
    auto not_exe = ServerProcess::start("/etc/hostname", {}, 2000);
    EXPECT_FALSE(not_exe.ok());
}

TEST(SpawnProcess, WiresTheChildsStandardInputAndOutputToTheGivenDescriptors) {
    int to_child[2], from_child[2];
    ASSERT_EQ(::pipe2(to_child, O_CLOEXEC), 0);
    ASSERT_EQ(::pipe2(from_child, O_CLOEXEC), 0);
    const auto pid = spawnProcess({"/bin/sh", "-c", "read line; echo \"got $line\""}, to_child[0],
                                  from_child[1]);
    ::close(to_child[0]);
    ::close(from_child[1]);
    ASSERT_TRUE(pid.ok()) << pid.error();
    ASSERT_EQ(::write(to_child[1], "hi\n", 3), 3);
    ::close(to_child[1]);
    std::string out;
    char c = 0;
    while (::read(from_child[0], &c, 1) == 1)
        out += c;
    ::close(from_child[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(*pid, &status, 0), *pid);
    EXPECT_EQ(out, "got hi\n");
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST(SpawnProcess, SaysWhyWhenTheExecutableCannotStart) {
    const auto pid = spawnProcess({"/nonexistent/qvr-spawn"}, -1, -1);
    ASSERT_FALSE(pid.ok());
    EXPECT_NE(pid.error().find("No such file"), std::string::npos) << pid.error();
}

TEST(ServerProcess, MovingTransfersOwnershipOfTheChild) {
    const std::string ready = "echo 'qvr server: listening on 127.0.0.1:41000'; exec sleep 30";
    auto a = startShell(ready);
    ASSERT_TRUE(a.ok()) << a.error();
    const pid_t pid = a->pid();
    std::optional<ServerProcess> moved;
    {
        ServerProcess from = std::move(*a);
        moved.emplace(std::move(from));
        EXPECT_EQ(from.pid(), -1);
        EXPECT_EQ(from.stop(), -1);  // the moved-from object owns nothing
    }                                // `from` destroyed here, `*a` is moved-from as well
    a = makeError("dropped");
    std::this_thread::sleep_for(50ms);
    EXPECT_TRUE(alive(pid)) << "a moved-from destructor killed the child";
    EXPECT_EQ(moved->pid(), pid);
    EXPECT_EQ(moved->port(), 41000);

    // Move assignment stops what the target held and takes the source's child.
    auto b = startShell("echo 'qvr server: listening on 127.0.0.1:42000'; exec sleep 30");
    ASSERT_TRUE(b.ok()) << b.error();
    const pid_t pid_b = b->pid();
    *moved = std::move(*b);
    EXPECT_FALSE(alive(pid)) << "the assigned-over child was left running";
    EXPECT_EQ(moved->pid(), pid_b);
    EXPECT_EQ(moved->port(), 42000);
    b = makeError("dropped");
    EXPECT_TRUE(alive(pid_b));
    moved.reset();  // the owner's destructor stops it
    EXPECT_FALSE(alive(pid_b));
}

// A descendant that inherited the pipe (here a background sleep) must not hold start() past
// ready_timeout_ms + the stop grace.
TEST(ServerProcess, TimesOutPromptlyWhenADescendantHoldsTheOutput) {
    const auto t0 = Clock::now();
    auto sp = startShell("sleep 4 & exec sleep 30", 300);
    EXPECT_FALSE(sp.ok());
    EXPECT_LT(msSince(t0), 2000);
}

// After the ready line the child's output is passed through as it comes, so a child that prints
// more than the pipe holds (64 KiB) does not block in write().
TEST(ServerProcess, ChildIsNotBlockedByOutputAfterTheReadyLine) {
    const Scratch s;
    // Keep the 400 KB the child prints out of the test log.
    std::fflush(stdout);
    const int saved = ::dup(STDOUT_FILENO);
    const int null_fd = ::open("/dev/null", O_WRONLY);
    ::dup2(null_fd, STDOUT_FILENO);
    auto sp = startShell(
        "echo 'qvr server: listening on 127.0.0.1:43000'; yes 'qvr server: frame stats' | "
        "head -n 20000; touch " +
        s.path("done") + "; exec sleep 30");
    bool done = false;
    if (sp.ok()) {
        const auto deadline = Clock::now() + 3s;
        while (!std::filesystem::exists(s.path("done")) && Clock::now() < deadline)
            std::this_thread::sleep_for(20ms);
        done = std::filesystem::exists(s.path("done"));
        sp->stop(300);
    }
    std::fflush(stdout);
    ::dup2(saved, STDOUT_FILENO);
    ::close(null_fd);
    ::close(saved);
    ASSERT_TRUE(sp.ok()) << sp.error();
    EXPECT_TRUE(done) << "the child is stuck writing";
}

// A port with trailing characters is not a port.
TEST(ServerProcess, RejectsAPortWithTrailingCharacters) {
    auto sp =
        startShell("echo 'qvr server: listening on 127.0.0.1:8080x (x)'; exec sleep 30", 2000);
    ASSERT_FALSE(sp.ok());
    EXPECT_NE(sp.error().find("unreadable ready line"), std::string::npos) << sp.error();
}

}  // namespace
}  // namespace qvr::runtime
