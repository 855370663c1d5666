// The co-running load's and the speed probe's child process, from the parent's side
// (corun_load.h).
#include "corun_load.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "qvr/runtime/server_process.h"

namespace qvr::experiment {

Expected<std::unique_ptr<CoRunLoad>> CoRunLoad::start(const CalibrateOptions& o, int core,
                                                      const std::string& mix) {
    const auto self = runtime::selfExecutable();
    if (!self)
        return makeError(self.error());
    const std::string& exe = *self;
    int to_child[2], from_child[2];
    if (pipe2(to_child, O_CLOEXEC) != 0)
        return makeError(std::string("pipe: ") + std::strerror(errno));
    if (pipe2(from_child, O_CLOEXEC) != 0) {
        ::close(to_child[0]);
        ::close(to_child[1]);
        return makeError(std::string("pipe: ") + std::strerror(errno));
    }
    std::vector<std::string> args{exe,         "corun-load",
                                  "--scene",   o.scene,
                                  "--profile", o.profile,
                                  "--lod-px",  fmt::format("{}", o.lod_px),
                                  "--core",    std::to_string(core),
                                  "--codec",   o.codec,
                                  "--mix",     mix};
    const auto pid = runtime::spawnProcess(std::move(args), to_child[0], from_child[1]);
    ::close(to_child[0]);
    ::close(from_child[1]);
    auto load =
        std::unique_ptr<CoRunLoad>(new CoRunLoad(pid ? *pid : -1, to_child[1], from_child[0]));
    if (!pid)
        return makeError("cannot start " + exe + ": " + pid.error());
    // Its ready line, once the scene is loaded (a minute at most).
    std::string line;
    char c = 0;
    for (;;) {
        pollfd pfd{load->m_out, POLLIN, 0};
        if (::poll(&pfd, 1, 60'000) <= 0)
            return makeError("the load process was not ready within 60 s");
        if (::read(load->m_out, &c, 1) != 1)
            return makeError("the load process ended before it was ready");
        if (c == '\n')
            break;
        line += c;
    }
    if (line != "ready")
        return makeError("the load process: " + line);
    return load;
}

Status CoRunLoad::setBusy(bool busy) {
    const char cmd[2] = {busy ? '1' : '0', '\n'};
    if (!writeTwo(cmd))
        return makeError("cannot write to the load process");
    char c = 0;
    pollfd pfd{m_out, POLLIN, 0};
    if (::poll(&pfd, 1, 60'000) <= 0 || ::read(m_out, &c, 1) != 1)
        return makeError("the load process did not answer");
    return {};
}

Expected<SpeedSample> CoRunLoad::probe() {
    if (!writeTwo("p\n"))
        return makeError("cannot write to the speed probe process");
    std::string line;
    for (char c = 0;;) {
        pollfd pfd{m_out, POLLIN, 0};
        if (::poll(&pfd, 1, 60'000) <= 0 || ::read(m_out, &c, 1) != 1)
            return makeError("the speed probe process did not answer");
        if (c == '\n')
            break;
        if (line.size() > 200)
            return makeError("the speed probe process answered garbage");
        line += c;
    }
    SpeedSample sample;
    if (std::sscanf(line.c_str(), "%lf %lf", &sample.headset_ms, &sample.server_ms) != 2 ||
        !(sample.headset_ms > 0.0) || !(sample.server_ms > 0.0))
        return makeError("the speed probe process: " + line);
    return sample;
}

void CoRunLoad::stop() {
    if (m_in >= 0)
        ::close(m_in);
    m_in = -1;
    if (m_pid > 0) {
        int status = 0;
        for (int k = 0; k < 500 && ::waitpid(m_pid, &status, WNOHANG) == 0; ++k)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (::waitpid(m_pid, &status, WNOHANG) == 0) {
            ::kill(m_pid, SIGKILL);
            ::waitpid(m_pid, &status, 0);
        }
    }
    m_pid = -1;
}

CoRunLoad::~CoRunLoad() {
    stop();
    if (m_out >= 0)
        ::close(m_out);
}

bool CoRunLoad::writeTwo(const char* bytes) {
    sigset_t pipe_set, old_set;
    sigemptyset(&pipe_set);
    sigaddset(&pipe_set, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_set, &old_set);
    const ssize_t written = ::write(m_in, bytes, 2);
    if (written != 2 && errno == EPIPE) {
        const timespec zero{0, 0};
        sigtimedwait(&pipe_set, nullptr, &zero);
    }
    pthread_sigmask(SIG_SETMASK, &old_set, nullptr);
    return written == 2;
}

}  // namespace qvr::experiment
