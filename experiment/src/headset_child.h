// The extra headsets of `qvr run --headsets N`: each in a child process of its own (`qvr
// run-headset`, internal), so it has its own GL stack as a headset has its own device
// (server_process.h says why one process would share llvmpipe's rasterizers). The parent sends
// the session's settings and key as one JSON line on the child's stdin; the child loads its scene
// and traces, makes its renderer, says "ready" and waits for "go", so every headset's first
// frame starts together; at the end it writes its telemetry CSV and summary JSON and sends the
// summary back as "result JSON". Internal to the experiment part.
#pragma once

#include <sys/types.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/experiment/headsets.h"
#include "qvr/experiment/run_plan.h"
#include "qvr/runtime/cpu_share.h"

namespace qvr::experiment {

class HeadsetChild {
public:
    // Spawned, `settings` sent (see runHeadsetChild for its keys).
    static Expected<std::unique_ptr<HeadsetChild>> start(const nlohmann::json& settings);
    ~HeadsetChild();
    HeadsetChild(const HeadsetChild&) = delete;
    HeadsetChild& operator=(const HeadsetChild&) = delete;

    pid_t pid() const { return m_pid; }
    // Waits for its "ready" line; an error when it reported one, ended or took longer.
    Status waitReady(int timeout_ms);
    // Starts its frames.
    void go();
    // Waits for its result line and its exit; an error when it had none.
    Expected<runtime::DesignSummary> finish(int timeout_ms);

private:
    HeadsetChild(pid_t pid, int fd) : m_pid(pid), m_fd(fd) {}
    Expected<std::string> readLine(int timeout_ms);
    void reap();
    pid_t m_pid;
    int m_fd;  // a socket: stdin and stdout of the child
    std::string m_pending;
};

// Headsets 1…N−1 of a run, one design at a time: started before headset 0's session, released
// together at its first frame, collected after it.
class OtherHeadsets {
public:
    // Each headset's CPU share group (plan.headset_share under 1) is made here, once.
    static Expected<std::unique_ptr<OtherHeadsets>> make(const RunOptions& plan,
                                                         std::vector<HeadsetWorkload> workloads,
                                                         int core);
    // Starts one process per headset for `design` against the server on `port`.
    Status start(const std::string& design, uint16_t port, const std::string& key_hex);
    // Waits for each to be ready (a minute at most) and lets them all start their frames.
    void release();
    // Each headset's outcome once its session ended (stopped: they are ended, not awaited).
    std::vector<HeadsetOutcome> collect(bool stopped);

private:
    OtherHeadsets(const RunOptions& plan, std::vector<HeadsetWorkload> workloads, int core)
        : m_plan(plan), m_workloads(std::move(workloads)), m_core(core) {}
    nlohmann::json settings(size_t k, const std::string& design, uint16_t port,
                            const std::string& key_hex) const;
    const RunOptions& m_plan;
    std::vector<HeadsetWorkload> m_workloads;  // [0] is headset 0's, run in the parent
    int m_core;
    std::vector<std::optional<runtime::CpuShareGroup>> m_groups;  // by headset
    std::vector<std::unique_ptr<HeadsetChild>> m_children;        // by headset, [0] empty
    std::vector<std::string> m_errors;                            // by headset
};

// A summary as the child sends it, and back.
nlohmann::json summaryToJson(const runtime::DesignSummary& s);
runtime::DesignSummary summaryFromJson(const nlohmann::json& j);

}  // namespace qvr::experiment
