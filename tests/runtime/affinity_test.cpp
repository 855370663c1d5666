// ScopedThreadPin (affinity.h): what `qvr run`'s main thread holds while the designs run. The
// threads made under the pin — a plain thread, and llvmpipe's rasterizers for a GL context made
// on the pinned thread — run on the pinned core only, and the thread gets its mask back after.
// Before the pin, the quality pass's context made those rasterizers on the unpinned main thread
// and every design after the first rendered its fovea on the server's core as well.
#include "qvr/runtime/affinity.h"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>
#include <sys/types.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "qvr/render/gl_renderer.h"

namespace qvr::runtime {
namespace {

std::set<int> cpusOf(pid_t tid) {
    cpu_set_t set;
    CPU_ZERO(&set);
    std::set<int> cpus;
    if (sched_getaffinity(tid, sizeof(set), &set) != 0)
        return cpus;
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &set))
            cpus.insert(c);
    return cpus;
}

std::set<pid_t> processThreads() {
    std::set<pid_t> tids;
    for (const auto& e : std::filesystem::directory_iterator("/proc/self/task"))
        tids.insert(static_cast<pid_t>(std::stol(e.path().filename().string())));
    return tids;
}

std::string threadName(pid_t tid) {
    std::ifstream f("/proc/self/task/" + std::to_string(tid) + "/comm");
    std::string name;
    std::getline(f, name);
    return name;
}

TEST(Affinity, ThreadsMadeUnderAPinRunOnItsCoreAndTheMaskComesBack) {
    if (onlineCores() < 2)
        GTEST_SKIP() << "one core: nothing to pin apart";
    const std::set<int> before = cpusOf(0);
    ASSERT_GE(before.size(), 2u) << "this test needs an unpinned thread to start from";
    const int core = *before.rbegin();
    const std::set<pid_t> existing = processThreads();
    {
        ScopedThreadPin pin(core);
        ASSERT_TRUE(pin.error().empty()) << pin.error();
        EXPECT_EQ(cpusOf(0), std::set<int>{core});
        std::set<int> child;
        std::thread t([&] { child = cpusOf(0); });
        t.join();
        EXPECT_EQ(child, std::set<int>{core});
        // A GL context made here: whatever threads the driver starts for it stay on the core.
        auto renderer = GlRenderer::create();
        ASSERT_TRUE(renderer) << renderer.error();
        for (pid_t tid : processThreads()) {
            if (existing.count(tid))
                continue;
            // Mesa's shader-cache writer asks for every core on purpose (util_queue's
            // SET_FULL_THREAD_AFFINITY); it writes compiled shaders to disk and is idle after.
            if (threadName(tid).find("disk$") != std::string::npos)
                continue;
            const std::set<int> cpus = cpusOf(tid);
            if (cpus.empty())
                continue;  // ended meanwhile
            EXPECT_EQ(cpus, std::set<int>{core}) << "thread " << tid << " of the GL context";
        }
    }
    EXPECT_EQ(cpusOf(0), before);
}

TEST(Affinity, APinToACoreThatDoesNotExistSaysWhyAndChangesNothing) {
    const std::set<int> before = cpusOf(0);
    {
        ScopedThreadPin pin(CPU_SETSIZE + 5);
        EXPECT_NE(pin.error().find("out of range"), std::string::npos) << pin.error();
        EXPECT_EQ(cpusOf(0), before);
    }
    EXPECT_EQ(cpusOf(0), before);
}

TEST(Affinity, AllowedCoresFollowTheMaskNotTheOnlineCount) {
    const std::set<int> before = cpusOf(0);
    const std::vector<int> all = allowedCores();
    EXPECT_EQ(std::set<int>(all.begin(), all.end()), before);
    EXPECT_TRUE(std::is_sorted(all.begin(), all.end()));
    const int last = *before.rbegin();
    {
        ScopedThreadPin pin(last);
        ASSERT_TRUE(pin.error().empty()) << pin.error();
        EXPECT_EQ(allowedCores(), std::vector<int>{last});
    }
    EXPECT_EQ(allowedCores(), all);
}

}  // namespace
}  // namespace qvr::runtime
