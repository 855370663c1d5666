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

// cpuQuotaShare reads what a group allows from the process's cgroup file: the quota of its own
// group and of the groups above it, the smallest winning (LIWC's L under a quota, docs/LIWC.md).
class CpuQuotaShare : public CpuShareRoot {
protected:
    std::string procFile(const std::string& text) {
        const fs::path p = m_root / "proc_cgroup";
        std::ofstream(p) << text;
        return p.string();
    }
    void quota(const std::string& group, long long quota_us, long long period_us) {
        fs::create_directories(m_root / group);
        std::ofstream(m_root / group / "cpu.cfs_quota_us") << quota_us << "\n";
        std::ofstream(m_root / group / "cpu.cfs_period_us") << period_us << "\n";
    }
};

TEST_F(CpuQuotaShare, ReadsTheSmallestQuotaOfTheGroupAndItsParentsV1) {
    quota("a", 50'000, 100'000);
    quota("a/b", 3'000, 10'000);
    const std::string proc = procFile("4:memory:/x\n1:cpu,cpuacct:/a/b\n0::/\n");
    EXPECT_DOUBLE_EQ(cpuQuotaShare(proc, m_root.string()), 0.3);
    quota("a", 20'000, 100'000);
    EXPECT_DOUBLE_EQ(cpuQuotaShare(proc, m_root.string()), 0.2);
    // More than a core is a whole core for the one core the headset is pinned to.
    quota("a", -1, 100'000);
    quota("a/b", 30'000, 10'000);
    EXPECT_DOUBLE_EQ(cpuQuotaShare(proc, m_root.string()), 1.0);
}

TEST_F(CpuQuotaShare, ReadsCpuMaxV2) {
    fs::create_directories(m_root / "g");
    std::ofstream(m_root / "g" / "cpu.max") << "30000 100000\n";
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("0::/g\n"), m_root.string()), 0.3);
    std::ofstream(m_root / "g" / "cpu.max") << "max 100000\n";
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("0::/g\n"), m_root.string()), 1.0);
}

TEST_F(CpuQuotaShare, AnUnreadableOrMalformedCgroupIsNoQuota) {
    quota("a", 3'000, 10'000);
    EXPECT_DOUBLE_EQ(cpuQuotaShare((m_root / "missing").string(), m_root.string()), 1.0);
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("garbage\n1:cpu\n::\n1:cpu:a\n"), m_root.string()),
                     1.0);
    // The group named has no quota files: nothing to read.
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("1:cpu:/nowhere\n"), m_root.string()), 1.0);
    std::ofstream(m_root / "a" / "cpu.cfs_quota_us") << "lots\n";
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("1:cpu:/a\n"), m_root.string()), 1.0);
    fs::create_directories(m_root / "g");
    std::ofstream(m_root / "g" / "cpu.max") << "x 100000\n";
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("0::/g\n"), m_root.string()), 1.0);
    // A quota below the smallest share a group may have reads as that share.
    quota("a", 10, 10'000);
    EXPECT_DOUBLE_EQ(cpuQuotaShare(procFile("1:cpu:/a\n"), m_root.string()),
                     CpuShareGroup::kMinShare);
}

}  // namespace
}  // namespace qvr::runtime
