// An extra headset of `qvr run --headsets N` in its own process, both sides (headset_child.h).
#include "headset_child.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "qvr/core/design.h"
#include "qvr/core/text_file.h"
#include "qvr/experiment/run_experiment.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/server_process.h"
#include "qvr/runtime/session.h"

extern char** environ;

namespace qvr::experiment {

using namespace qvr::runtime;
namespace fs = std::filesystem;

namespace {

// The fields of a summary the child sends its parent, each with its key: summaryToJson writes
// them and summaryFromJson reads them, so the two sides cannot drift apart.
template <typename Summary, typename Visit>
void visitSentFields(Summary& s, Visit visit) {
    visit("design", s.design);
    visit("frames", s.frames);
    visit("frames_displayed", s.frames_displayed);
    visit("frames_reused", s.frames_reused);
    visit("frames_new_layers", s.frames_new_layers);
    visit("frames_remote_requested", s.frames_remote_requested);
    visit("fps_mean", s.fps_mean);
    visit("mtp_ms_mean", s.mtp_ms_mean);
    visit("mtp_ms_p99", s.mtp_ms_p99);
    visit("bytes_per_frame_mean", s.bytes_per_frame_mean);
    visit("e1_deg_mean", s.e1_deg_mean);
    visit("t_local_ms_mean", s.t_local_ms_mean);
    visit("t_remote_ms_mean", s.t_remote_ms_mean);
    visit("headset_busy_ms_mean", s.headset_busy_ms_mean);
    visit("warmup_frames", s.warmup_frames);
    visit("startup_unfinished", s.startup_unfinished);
}

}  // namespace

nlohmann::json summaryToJson(const DesignSummary& s) {
    nlohmann::json j = nlohmann::json::object();
    visitSentFields(s, [&j](const char* key, const auto& value) { j[key] = value; });
    return j;
}

DesignSummary summaryFromJson(const nlohmann::json& j) {
    DesignSummary s;
    // A key the child did not send leaves the field at zero (an empty design name).
    visitSentFields(s, [&j](const char* key, auto& value) {
        value = j.value(key, std::decay_t<decltype(value)>{});
    });
    return s;
}

// ---- the parent's side ----

Expected<std::unique_ptr<HeadsetChild>> HeadsetChild::start(const nlohmann::json& settings) {
    auto exe = selfExecutable();
    if (!exe)
        return makeError(exe.error());
    int fds[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
        return makeError(std::string("socketpair: ") + std::strerror(errno));
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    std::vector<std::string> args{*exe, "run-headset"};
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, exe->c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    if (rc != 0) {
        ::close(fds[0]);
        return makeError("cannot start " + *exe + ": " + std::strerror(rc));
    }
    auto child = std::unique_ptr<HeadsetChild>(new HeadsetChild(pid, fds[0]));
    const std::string line = settings.dump() + "\n";
    if (::send(fds[0], line.data(), line.size(), MSG_NOSIGNAL) != ssize_t(line.size()))
        return makeError("cannot send the headset its settings");
    return child;
}

HeadsetChild::~HeadsetChild() {
    if (m_fd >= 0)
        ::close(m_fd);
    m_fd = -1;
    if (m_pid > 0) {
        ::kill(m_pid, SIGKILL);
        reap();
    }
}

void HeadsetChild::reap() {
    int status = 0;
    while (m_pid > 0 && waitpid(m_pid, &status, 0) < 0 && errno == EINTR) {
    }
    m_pid = -1;
}

Expected<std::string> HeadsetChild::readLine(int timeout_ms) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    for (;;) {
        if (const size_t nl = m_pending.find('\n'); nl != std::string::npos) {
            std::string line = m_pending.substr(0, nl);
            m_pending.erase(0, nl + 1);
            return line;
        }
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                              deadline - std::chrono::steady_clock::now())
                              .count();
        if (left <= 0)
            return makeError("no answer within " + std::to_string(timeout_ms / 1000) + " s");
        pollfd p{m_fd, POLLIN, 0};
        if (::poll(&p, 1, int(left)) < 0 && errno != EINTR)
            return makeError(std::string("poll: ") + std::strerror(errno));
        if (!(p.revents & (POLLIN | POLLHUP)))
            continue;
        char buf[4096];
        const ssize_t n = ::read(m_fd, buf, sizeof buf);
        if (n <= 0)
            return makeError("the headset process ended");
        m_pending.append(buf, size_t(n));
    }
}

Status HeadsetChild::waitReady(int timeout_ms) {
    for (;;) {
        auto line = readLine(timeout_ms);
        if (!line)
            return makeError(line.error());
        if (*line == "ready")
            return {};
        if (line->rfind("error ", 0) == 0)
            return makeError(line->substr(6));
    }
}

void HeadsetChild::go() {
    [[maybe_unused]] const ssize_t n = ::send(m_fd, "g", 1, MSG_NOSIGNAL);
}

Expected<DesignSummary> HeadsetChild::finish(int timeout_ms) {
    for (;;) {
        auto line = readLine(timeout_ms);
        if (!line)
            return makeError(line.error());
        if (line->rfind("error ", 0) == 0)
            return makeError(line->substr(6));
        if (line->rfind("result ", 0) != 0)
            continue;
        const auto j = nlohmann::json::parse(line->substr(7), nullptr, false);
        if (j.is_discarded())
            return makeError("an unreadable result line");
        reap();
        return summaryFromJson(j);
    }
}

// ---- headsets 1…N−1 ----

Expected<std::unique_ptr<OtherHeadsets>> OtherHeadsets::make(const RunOptions& plan,
                                                             std::vector<HeadsetWorkload> workloads,
                                                             int core) {
    auto others =
        std::unique_ptr<OtherHeadsets>(new OtherHeadsets(plan, std::move(workloads), core));
    others->m_groups.resize(others->m_workloads.size());
    if (plan.headset_share < 1.0)
        for (size_t k = 1; k < others->m_groups.size(); ++k) {
            auto g = CpuShareGroup::create(plan.headset_share);
            if (!g)
                return makeError(g.error());
            others->m_groups[k] = std::move(*g);
        }
    return others;
}

nlohmann::json OtherHeadsets::settings(size_t k, const std::string& design, uint16_t port,
                                       const std::string& key_hex) const {
    const fs::path dir = fs::path(m_plan.out) / fmt::format("headset{}", k);
    std::error_code ec;
    fs::create_directories(dir, ec);
    const HeadsetWorkload& w = m_workloads[k];
    return {{"scene", m_plan.scene},
            {"profile", m_plan.profile},
            {"codec", m_plan.codec},
            {"lod_px", m_plan.lod_px},
            {"design", design},
            {"frames", m_plan.frames},
            {"warmup_frames", m_plan.warmup_frames},
            {"pipeline_depth", m_plan.pipeline_depth},
            {"remote_timeout_ms", m_plan.remote_timeout_ms},
            {"ring_counts", m_plan.ring_counts},
            {"port", port},
            {"key", key_hex},
            {"core", m_core},
            {"motion", w.motion},
            {"gaze", w.gaze},
            {"seed", w.seed},
            {"ahead_ms", w.ahead_ms},
            {"telemetry_csv", (dir / fmt::format("frames_{}.csv", design)).string()},
            {"summary_json", (dir / fmt::format("summary_{}.json", design)).string()}};
}

Status OtherHeadsets::start(const std::string& design, uint16_t port, const std::string& key_hex) {
    m_children.clear();
    m_children.resize(m_workloads.size());
    m_errors.assign(m_workloads.size(), std::string());
    for (size_t k = 1; k < m_workloads.size(); ++k) {
        auto child = HeadsetChild::start(settings(k, design, port, key_hex));
        if (!child)
            return makeError(fmt::format("headset {}: {}", k, child.error()));
        if (m_groups[k])
            if (auto st = m_groups[k]->addProcess((*child)->pid()); !st)
                return makeError(fmt::format("headset {}: --headset-share: {}", k, st.error()));
        m_children[k] = std::move(*child);
    }
    return {};
}

void OtherHeadsets::release() {
    for (size_t k = 1; k < m_children.size(); ++k)
        if (auto st = m_children[k]->waitReady(60'000); !st) {
            m_errors[k] = st.error();
            m_children[k].reset();
        }
    for (auto& child : m_children)
        if (child)
            child->go();
}

std::vector<HeadsetOutcome> OtherHeadsets::collect(bool stopped) {
    std::vector<HeadsetOutcome> out;
    // Each frame a second at the very least, and a minute for the start-up.
    const int timeout_ms = 60'000 + 1000 * m_plan.frames;
    for (size_t k = 1; k < m_children.size(); ++k) {
        HeadsetOutcome h;
        h.index = int(k);
        h.workload = m_workloads[k];
        h.error = m_errors[k];
        if (stopped && h.error.empty())
            h.error = "the run was interrupted";
        if (h.error.empty() && m_children[k]) {
            if (auto summary = m_children[k]->finish(timeout_ms))
                h.summary = *summary;
            else
                h.error = summary.error();
        }
        out.push_back(std::move(h));
    }
    m_children.clear();  // any still running are ended
    return out;
}

// ---- the child's side ----

namespace {

std::atomic<bool> g_child_stop{false};

// The session's settings from the parent's line.
Expected<HeadsetConfig> childConfig(const nlohmann::json& s, HmdProfile& profile) {
    auto p = runtimeProfileByName(s.at("profile").get<std::string>());
    if (!p)
        return makeError(p.error());
    profile = *p;
    auto design = parseDesign(s.at("design").get<std::string>(), DesignScope::Runtime);
    if (!design)
        return makeError(design.error());
    auto key = net::PresharedKey::fromHex(s.at("key").get<std::string>());
    if (!key)
        return makeError(key.error());
    HeadsetConfig hc;
    hc.design = design->design;
    hc.fixed_e1_deg = design->fixed_e1_deg;
    hc.profile = profile;
    hc.codec.backend = s.at("codec").get<std::string>();
    hc.port = s.at("port").get<uint16_t>();
    hc.key = *key;
    hc.frames = s.at("frames").get<int>();
    hc.core = s.at("core").get<int>();
    hc.remote_timeout_ms = s.at("remote_timeout_ms").get<double>();
    hc.pipeline_depth = s.at("pipeline_depth").get<int>();
    hc.warmup_frames = s.at("warmup_frames").get<int>();
    hc.lod_error_px = s.at("lod_px").get<float>();
    hc.cluster_ring_counts = s.at("ring_counts").get<std::string>() == "clusters";
    hc.stop = &g_child_stop;
    GlRendererOptions gl;
    gl.lod_error_px = hc.lod_error_px;
    hc.renderer = glRendererFactory(gl);
    return hc;
}

Expected<HeadsetResult> childSession(const nlohmann::json& s) {
    if (const int core = s.at("core").get<int>(); core >= 0)
        if (auto st = pinCurrentThread(core); !st)
            return makeError(st.error());
    HmdProfile profile;
    auto hc = childConfig(s, profile);
    if (!hc)
        return makeError(hc.error());
    auto inputs =
        loadHeadsetInputs(s.at("scene").get<std::string>(), s.at("motion").get<std::string>(),
                          s.at("gaze").get<std::string>(), profile.refresh_hz, hc->frames,
                          s.at("seed").get<uint64_t>());
    if (!inputs)
        return makeError(inputs.error());
    playAhead(inputs->traces, s.at("ahead_ms").get<double>());
    // Ready once the renderer is made and the scene uploaded: the first frame is about to start.
    hc->before_frame = [](int64_t frame) {
        if (frame != 0)
            return;
        std::fputs("ready\n", stdout);
        std::fflush(stdout);
        char c = 0;
        if (::read(STDIN_FILENO, &c, 1) != 1)
            g_child_stop.store(true);  // the parent is gone
    };
    return runHeadset(*hc, inputs->scene, inputs->bvh, inputs->traces);
}

void childError(const std::string& message) {
    std::printf("error %s\n", message.c_str());
    std::fflush(stdout);
}

}  // namespace

int runHeadsetChild() {
    // Byte by byte: nothing past the line may be buffered, the "go" byte is read with read(2).
    std::string line;
    for (char c = 0; ::read(STDIN_FILENO, &c, 1) == 1 && c != '\n';)
        line += c;
    if (line.empty()) {
        childError("no settings");
        return 2;
    }
    const auto s = nlohmann::json::parse(line, nullptr, false);
    if (s.is_discarded()) {
        childError("unreadable settings");
        return 2;
    }
    Expected<HeadsetResult> result = makeError("not run");
    try {
        result = childSession(s);
    } catch (const nlohmann::json::exception& e) {
        result = makeError(std::string("settings: ") + e.what());
    }
    if (!result) {
        childError(result.error());
        return 1;
    }
    const nlohmann::json summary = summaryToJson(result->summary);
    const std::string label = result->summary.design;
    if (const std::string csv = s.value("telemetry_csv", ""); !csv.empty())
        if (auto st = writeTelemetryCsv(csv, label, result->frames); !st)
            std::fprintf(stderr, "qvr run-headset: %s\n", st.error().c_str());
    if (const std::string path = s.value("summary_json", ""); !path.empty())
        if (Status st = writeJsonFile(path, summary); !st)
            std::fprintf(stderr, "qvr run-headset: %s\n", st.error().c_str());
    std::printf("result %s\n", summary.dump().c_str());
    std::fflush(stdout);
    return 0;
}

}  // namespace qvr::experiment
