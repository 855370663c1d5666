// `qvr server` as a child process (server_process.h).
#include "qvr/runtime/server_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <thread>

extern char** environ;

namespace qvr::runtime {

namespace {

constexpr std::string_view kReadyPrefix = "qvr server: listening on ";

int waitExit(pid_t pid, int timeout_ms) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    for (;;) {
        int status = 0;
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid)
            return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        if (r < 0)
            return -1;
        if (std::chrono::steady_clock::now() >= deadline)
            return -2;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
}

// Copies whatever the child printed after its ready line to our stdout, without blocking.
void passThrough(int fd) {
    char buf[4096];
    for (;;) {
        const ssize_t n = read(fd, buf, sizeof buf);
        if (n <= 0)
            return;
        if (write(STDOUT_FILENO, buf, static_cast<size_t>(n)) < 0)
            return;
    }
}

}  // namespace

Expected<std::string> selfExecutable() {
    std::error_code ec;
    const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec)
        return makeError("cannot find the running executable: " + ec.message());
    return p.string();
}

Expected<ServerProcess> ServerProcess::start(const std::string& executable,
                                             const std::vector<std::string>& args,
                                             int ready_timeout_ms) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0)
        return makeError(std::string("server process: pipe: ") + std::strerror(errno));
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    std::vector<std::string> argv_s;
    argv_s.push_back(executable);
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_s)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, executable.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    if (rc != 0) {
        close(fds[0]);
        return makeError("server process: cannot start " + executable + ": " + std::strerror(rc));
    }
    ServerProcess sp;
    sp.m_pid = pid;
    sp.m_stdout_fd = fds[0];
    // Read lines until the ready line, the child's exit or the deadline.
    std::string pending;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(ready_timeout_ms);
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                              deadline - std::chrono::steady_clock::now())
                              .count();
        if (left <= 0) {
            sp.stop(1000);
            return makeError("server process: not ready after " + std::to_string(ready_timeout_ms) +
                             " ms");
        }
        pollfd p{sp.m_stdout_fd, POLLIN, 0};
        if (poll(&p, 1, static_cast<int>(std::min<long long>(left, 100))) < 0 && errno != EINTR)
            return makeError(std::string("server process: poll: ") + std::strerror(errno));
        if (p.revents & (POLLIN | POLLHUP)) {
            char buf[1024];
            const ssize_t n = read(sp.m_stdout_fd, buf, sizeof buf);
            if (n <= 0) {
                const int status = sp.stop(1000);
                return makeError("server process: exited before it was ready (status " +
                                 std::to_string(status) + ")");
            }
            pending.append(buf, static_cast<size_t>(n));
            // Bound what a chatty child can make us hold.
            if (pending.size() > 65536)
                pending.erase(0, pending.size() - 4096);
        }
        for (size_t nl; (nl = pending.find('\n')) != std::string::npos;) {
            const std::string line = pending.substr(0, nl);
            pending.erase(0, nl + 1);
            const size_t at = line.find(kReadyPrefix);
            if (at == std::string::npos) {
                std::fprintf(stdout, "%s\n", line.c_str());
                continue;
            }
            // "HOST:PORT (…)": the port follows the last ':' of the address.
            const std::string rest = line.substr(at + kReadyPrefix.size());
            const std::string addr = rest.substr(0, rest.find(' '));
            const size_t colon = addr.rfind(':');
            const long port = colon == std::string::npos ? -1 : std::atol(addr.c_str() + colon + 1);
            if (port <= 0 || port > 65535) {
                sp.stop(1000);
                return makeError("server process: unreadable ready line: " + line);
            }
            sp.m_port = static_cast<uint16_t>(port);
            fcntl(sp.m_stdout_fd, F_SETFL, fcntl(sp.m_stdout_fd, F_GETFL) | O_NONBLOCK);
            return sp;
        }
    }
}

ServerProcess::ServerProcess(ServerProcess&& o) noexcept
    : m_pid(o.m_pid), m_stdout_fd(o.m_stdout_fd), m_port(o.m_port) {
    o.m_pid = -1;
    o.m_stdout_fd = -1;
}

ServerProcess& ServerProcess::operator=(ServerProcess&& o) noexcept {
    if (this != &o) {
        stop();
        m_pid = o.m_pid;
        m_stdout_fd = o.m_stdout_fd;
        m_port = o.m_port;
        o.m_pid = -1;
        o.m_stdout_fd = -1;
    }
    return *this;
}

ServerProcess::~ServerProcess() {
    stop(1000);
}

int ServerProcess::stop(int grace_ms) {
    int status = -1;
    if (m_pid > 0) {
        kill(m_pid, SIGTERM);
        status = waitExit(m_pid, grace_ms);
        if (status == -2) {
            kill(m_pid, SIGKILL);
            status = waitExit(m_pid, 5000);
        }
        m_pid = -1;
    }
    if (m_stdout_fd >= 0) {
        passThrough(m_stdout_fd);
        close(m_stdout_fd);
        m_stdout_fd = -1;
    }
    return status;
}

}  // namespace qvr::runtime
