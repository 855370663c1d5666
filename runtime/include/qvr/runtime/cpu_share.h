// The headset's compute share: the paper's server is far stronger than its headset
// (Table 4 runs the headset GPU at 500, 400 and 300 MHz); here both sides get one identical
// core, so the headset's process is given a fraction of its core through the kernel's CFS
// bandwidth control — a cgroup's quota per period. A short period (10 ms) spreads the
// throttling over every frame instead of stalling one frame in a burst.
#pragma once

#include <sys/types.h>
#include <string>

#include "qvr/core/expected.h"

namespace qvr::runtime {

class CpuShareGroup {
public:
    static constexpr int kDefaultPeriodUs = 10'000;
    // Shares outside (kMinShare, 1] are refused: 1 means the whole core (no group needed).
    static constexpr double kMinShare = 0.05;

    // Makes a cgroup of its own (qvr-headset-<pid>-<n>: every call a new one; v1 cpu controller
    // at /sys/fs/cgroup/cpu, else v2 cpu.max) with quota share · period. An error naming the file
    // that could not be written when the cgroup cannot be made (not root, read-only cgroup fs, no
    // cpu controller).
    static Expected<CpuShareGroup> create(double share, int period_us = kDefaultPeriodUs,
                                          const std::string& root = "");
    CpuShareGroup(CpuShareGroup&& other) noexcept;
    CpuShareGroup& operator=(CpuShareGroup&& other) noexcept;
    CpuShareGroup(const CpuShareGroup&) = delete;
    CpuShareGroup& operator=(const CpuShareGroup&) = delete;
    // Moves any process still in the group back to the parent and removes the group.
    ~CpuShareGroup();

    // Moves every thread of the process (v1 cgroup.procs / v2 cgroup.procs) into the group;
    // threads it creates later are in the group too.
    Status addProcess(pid_t pid);
    // Moves only the calling thread (v1 tasks); v2 cannot move single threads of a process.
    Status addCurrentThread();

    double share() const { return m_share; }
    const std::string& path() const { return m_path; }
    // Throttled periods and throttled time so far (cpu.stat), for the report.
    struct Throttling {
        long long periods = 0;
        long long throttled_periods = 0;
        double throttled_ms = 0.0;
    };
    Throttling throttling() const;

private:
    CpuShareGroup() = default;
    void release();
    std::string m_path;    // the group's directory
    std::string m_parent;  // where its processes go back to
    bool m_v2 = false;
    double m_share = 1.0;
};

// The fraction of one core this process's cgroup allows it: the smallest quota / period of its
// cpu cgroup and the groups above it (v1 cpu.cfs_quota_us / cpu.cfs_period_us under the cpu
// controller's mount, v2 cpu.max), capped at 1. 1 when no quota is set or none can be read (a
// line or file it cannot parse is skipped). `proc_cgroup` is /proc/self/cgroup's path and `root`
// the cgroup mount (v1: the cpu controller's, default /sys/fs/cgroup/cpu; v2: /sys/fs/cgroup).
double cpuQuotaShare(const std::string& proc_cgroup = "/proc/self/cgroup",
                     const std::string& root = "");

}  // namespace qvr::runtime
