// CpuShareGroup (cpu_share.h) on a stand-in for the cgroup v1 cpu controller: a temporary folder
// with the controller's quota file, so the tests need neither root nor a writable cgroup mount.
// `qvr run --headsets N` makes one group per headset from one process; the groups were named by
// the process id alone, so all N headsets ran under a single headset's quota.
#include "qvr/runtime/cpu_share.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace qvr::runtime {
namespace {

namespace fs = std::filesystem;

class CpuShareRoot : public ::testing::Test {
protected:
    void SetUp() override {
        m_root = fs::temp_directory_path() /
                 ("qvr_cpu_share_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(m_root);
        fs::create_directories(m_root);
        std::ofstream(m_root / "cpu.cfs_quota_us") << "-1\n";
    }
    void TearDown() override { fs::remove_all(m_root); }

    static std::string read(const fs::path& p) {
        std::ifstream in(p);
        std::string s;
        in >> s;
        return s;
    }
    fs::path m_root;
};

TEST_F(CpuShareRoot, EveryGroupMadeByOneProcessHasItsOwnQuota) {
    auto a = CpuShareGroup::create(0.25, 10'000, m_root.string());
    auto b = CpuShareGroup::create(0.5, 10'000, m_root.string());
    ASSERT_TRUE(a) << a.error();
    ASSERT_TRUE(b) << b.error();
    EXPECT_NE(a->path(), b->path());
    EXPECT_EQ(read(fs::path(a->path()) / "cpu.cfs_quota_us"), "2500");
    EXPECT_EQ(read(fs::path(b->path()) / "cpu.cfs_quota_us"), "5000");
    EXPECT_EQ(read(fs::path(a->path()) / "cpu.cfs_period_us"), "10000");
    ASSERT_TRUE(a->addProcess(4242));
    ASSERT_TRUE(b->addProcess(4343));
    EXPECT_EQ(read(fs::path(a->path()) / "cgroup.procs"), "4242");
    EXPECT_EQ(read(fs::path(b->path()) / "cgroup.procs"), "4343");
}

TEST_F(CpuShareRoot, RefusesAShareOutsideItsRangeAndAPeriodOutsideItsRange) {
    for (double share : {0.0, 0.05, 1.5, -1.0})
        EXPECT_FALSE(CpuShareGroup::create(share, 10'000, m_root.string())) << share;
    EXPECT_FALSE(CpuShareGroup::create(0.5, 500, m_root.string()));
    EXPECT_FALSE(CpuShareGroup::create(0.5, 2'000'000, m_root.string()));
}

TEST_F(CpuShareRoot, SaysWhenThereIsNoCpuController) {
    fs::remove(m_root / "cpu.cfs_quota_us");
    auto g = CpuShareGroup::create(0.5, 10'000, m_root.string());
    ASSERT_FALSE(g);
    EXPECT_NE(g.error().find("no cgroup cpu controller"), std::string::npos) << g.error();
}

}  // namespace
}  // namespace qvr::runtime
