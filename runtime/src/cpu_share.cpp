// CFS bandwidth control through the cgroup file system (kernel Documentation/scheduler/
// sched-bwc.rst): cpu.cfs_quota_us / cpu.cfs_period_us in v1, "quota period" in cpu.max in v2.
#include "qvr/runtime/cpu_share.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <fmt/format.h>

namespace qvr::runtime {

namespace {

bool exists(const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0;
}

Status writeFile(const std::string& path, const std::string& text) {
    std::ofstream f(path);
    if (!f)
        return makeError(fmt::format("cannot open {} ({})", path, std::strerror(errno)));
    f << text;
    f.flush();
    if (!f)
        return makeError(
            fmt::format("cannot write '{}' to {} ({})", text, path, std::strerror(errno)));
    return {};
}

}  // namespace

Expected<CpuShareGroup> CpuShareGroup::create(double share, int period_us,
                                              const std::string& root) {
    if (!std::isfinite(share) || share <= kMinShare || share > 1.0)
        return makeError(fmt::format("headset share {} is outside ({}, 1]", share, kMinShare));
    if (period_us < 1000 || period_us > 1'000'000)
        return makeError(fmt::format("CFS period {} us is outside 1000…1000000", period_us));
    CpuShareGroup g;
    g.m_share = share;
    const std::string v1 = root.empty() ? "/sys/fs/cgroup/cpu" : root;
    const std::string v2 = root.empty() ? "/sys/fs/cgroup" : root;
    std::string base;
    if (exists(v1 + "/cpu.cfs_quota_us")) {
        base = v1;
    } else if (exists(v2 + "/cgroup.controllers")) {
        base = v2;
        g.m_v2 = true;
    } else {
        return makeError(
            "no cgroup cpu controller found (/sys/fs/cgroup/cpu/cpu.cfs_quota_us or a cgroup v2 "
            "mount): cannot limit the headset's share");
    }
    g.m_parent = base;
    // One group per call, not per process: `qvr run --headsets N` makes a group for each
    // headset from the same process, and a name by pid alone put all N headsets under one quota
    // (N headsets sharing one headset's share of the core).
    static std::atomic<unsigned> made{0};
    g.m_path = fmt::format("{}/qvr-headset-{}-{}", base, ::getpid(), made.fetch_add(1));
    if (::mkdir(g.m_path.c_str(), 0755) != 0 && errno != EEXIST)
        return makeError(
            fmt::format("cannot create the cgroup {} ({}): run as root, or without "
                        "--headset-share",
                        g.m_path, std::strerror(errno)));
    const long long quota_us = std::llround(share * period_us);
    Status st = g.m_v2 ? writeFile(g.m_path + "/cpu.max", fmt::format("{} {}", quota_us, period_us))
                       : Status{};
    if (!g.m_v2) {
        st = writeFile(g.m_path + "/cpu.cfs_period_us", std::to_string(period_us));
        if (st)
            st = writeFile(g.m_path + "/cpu.cfs_quota_us", std::to_string(quota_us));
    }
    if (!st) {
        const std::string msg = st.error();
        g.release();
        return makeError("cannot set the headset's CPU quota: " + msg);
    }
    return g;
}

CpuShareGroup::CpuShareGroup(CpuShareGroup&& other) noexcept {
    *this = std::move(other);
}

CpuShareGroup& CpuShareGroup::operator=(CpuShareGroup&& other) noexcept {
    if (this != &other) {
        release();
        m_path = std::move(other.m_path);
        m_parent = std::move(other.m_parent);
        m_v2 = other.m_v2;
        m_share = other.m_share;
        other.m_path.clear();
    }
    return *this;
}

CpuShareGroup::~CpuShareGroup() {
    release();
}

void CpuShareGroup::release() {
    if (m_path.empty())
        return;
    // A group with tasks cannot be removed: move them back to the parent first.
    for (const char* file : {"cgroup.procs", "tasks"}) {
        std::ifstream in(m_path + "/" + file);
        std::string id;
        while (in >> id) {
            std::ofstream out(m_parent + "/" + file);
            out << id;
        }
    }
    ::rmdir(m_path.c_str());
    m_path.clear();
}

Status CpuShareGroup::addProcess(pid_t pid) {
    if (m_path.empty())
        return makeError("cpu share group: not created");
    return writeFile(m_path + "/cgroup.procs", std::to_string(pid));
}

Status CpuShareGroup::addCurrentThread() {
    if (m_path.empty())
        return makeError("cpu share group: not created");
    if (m_v2)
        return makeError("cgroup v2 moves whole processes only");
    return writeFile(m_path + "/tasks", std::to_string(::syscall(SYS_gettid)));
}

CpuShareGroup::Throttling CpuShareGroup::throttling() const {
    Throttling t;
    std::ifstream in(m_path + "/cpu.stat");
    std::string key;
    long long v = 0;
    while (in >> key >> v) {
        if (key == "nr_periods")
            t.periods = v;
        else if (key == "nr_throttled")
            t.throttled_periods = v;
        else if (key == "throttled_time")  // v1: ns
            t.throttled_ms = double(v) * 1e-6;
        else if (key == "throttled_usec")  // v2
            t.throttled_ms = double(v) * 1e-3;
    }
    return t;
}

namespace {

// quota / period of one group's directory; nullopt when it sets none or cannot be read.
std::optional<double> groupShare(const std::string& dir, bool v2) {
    long long quota = -1, period = 0;
    if (v2) {
        std::ifstream in(dir + "/cpu.max");
        std::string q;
        if (!(in >> q >> period) || q == "max")
            return std::nullopt;
        try {
            quota = std::stoll(q);
        } catch (const std::exception&) {
            return std::nullopt;
        }
    } else {
        std::ifstream q(dir + "/cpu.cfs_quota_us"), p(dir + "/cpu.cfs_period_us");
        if (!(q >> quota) || !(p >> period))
            return std::nullopt;
    }
    if (quota <= 0 || period <= 0)
        return std::nullopt;
    return double(quota) / double(period);
}

// The smallest share of `path` and the groups above it, under `base`.
double shareAlong(const std::string& base, std::string path, bool v2) {
    double share = 1.0;
    while (true) {
        if (auto s = groupShare(base + path, v2))
            share = std::min(share, *s);
        if (path.empty() || path == "/")
            break;
        const size_t slash = path.find_last_of('/');
        path = slash == std::string::npos ? std::string() : path.substr(0, slash);
    }
    return share;
}

}  // namespace

double cpuQuotaShare(const std::string& proc_cgroup, const std::string& root) {
    // Each line: hierarchy-id:controllers:path (man 7 cgroups). v1 names "cpu" among the
    // controllers; v2 is the line "0::path".
    std::ifstream in(proc_cgroup);
    std::string line;
    double share = 1.0;
    while (std::getline(in, line)) {
        const size_t a = line.find(':');
        const size_t b = a == std::string::npos ? a : line.find(':', a + 1);
        if (b == std::string::npos || b + 1 >= line.size() || line[b + 1] != '/')
            continue;
        const std::string controllers = line.substr(a + 1, b - a - 1);
        const std::string path = line.substr(b + 1);
        std::istringstream names(controllers);
        bool cpu = false;
        for (std::string n; std::getline(names, n, ',');)
            cpu = cpu || n == "cpu";
        if (cpu)
            share = std::min(share,
                             shareAlong(root.empty() ? "/sys/fs/cgroup/cpu" : root, path, false));
        else if (controllers.empty() && line.compare(0, a, "0") == 0)
            share = std::min(share, shareAlong(root.empty() ? "/sys/fs/cgroup" : root, path, true));
    }
    return std::clamp(share, CpuShareGroup::kMinShare, 1.0);
}

}  // namespace qvr::runtime
