// `qvr server` as a child process (server_process.h).
#include "qvr/runtime/server_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
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

// Copies what the child has printed so far to our stdout, without blocking.
void drainTo(int fd) {
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

Expected<pid_t> spawnProcess(std::vector<std::string> argv, int stdin_fd, int stdout_fd) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (stdin_fd != -1)
        posix_spawn_file_actions_adddup2(&actions, stdin_fd, STDIN_FILENO);
    if (stdout_fd != -1)
        posix_spawn_file_actions_adddup2(&actions, stdout_fd, STDOUT_FILENO);
    std::vector<char*> argv_c;
    for (std::string& a : argv)
        argv_c.push_back(a.data());
    argv_c.push_back(nullptr);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, argv_c.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0)
        return makeError(std::strerror(rc));
    return pid;
}

struct ServerProcess::Impl {
    pid_t pid = -1;
    int stdout_fd = -1;  // non-blocking once the child is ready
    uint16_t port = 0;
    std::atomic<bool> stop_reader{false};
    std::thread reader;  // passes the child's output through after the ready line

    void startReader() {
        reader = std::thread([this] {
            while (!stop_reader.load()) {
                pollfd p{stdout_fd, POLLIN, 0};
                const int r = poll(&p, 1, 100);
                if (r < 0 && errno != EINTR)
                    return;
                if (r > 0 && (p.revents & POLLIN))
                    drainTo(stdout_fd);
                else if (r > 0 && (p.revents & (POLLHUP | POLLERR)))
                    return;  // every writer is gone
            }
        });
    }

    int stop(int grace_ms) {
        int status = -1;
        if (pid > 0) {
            kill(pid, SIGTERM);
            status = waitExit(pid, grace_ms);
            if (status == -2) {
                kill(pid, SIGKILL);
                status = waitExit(pid, 5000);
            }
            pid = -1;
        }
        stop_reader = true;
        if (reader.joinable())
            reader.join();
        if (stdout_fd >= 0) {
            // Non-blocking: a descendant that kept the pipe open must not hold us here.
            fcntl(stdout_fd, F_SETFL, fcntl(stdout_fd, F_GETFL) | O_NONBLOCK);
            drainTo(stdout_fd);
            close(stdout_fd);
            stdout_fd = -1;
        }
        return status;
    }
};

namespace {

// "HOST:PORT (…)" → PORT, or 0 when there is no whole number in 1…65535 after the last ':'.
uint16_t portOfAddress(const std::string& rest) {
    const std::string addr = rest.substr(0, rest.find(' '));
    const size_t colon = addr.rfind(':');
    if (colon == std::string::npos || colon + 1 >= addr.size())
        return 0;
    const char* digits = addr.c_str() + colon + 1;
    char* end = nullptr;
    errno = 0;
    const long port = std::strtol(digits, &end, 10);
    if (errno != 0 || end == digits || *end != '\0' || port <= 0 || port > 65535 ||
        !std::isdigit(static_cast<unsigned char>(*digits)))
        return 0;
    return static_cast<uint16_t>(port);
}

}  // namespace

Expected<ServerProcess> ServerProcess::start(const std::string& executable,
                                             const std::vector<std::string>& args,
                                             int ready_timeout_ms) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0)
        return makeError(std::string("server process: pipe: ") + std::strerror(errno));
    std::vector<std::string> argv{executable};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto pid = spawnProcess(std::move(argv), -1, fds[1]);
    close(fds[1]);
    if (!pid) {
        close(fds[0]);
        return makeError("server process: cannot start " + executable + ": " + pid.error());
    }
    auto impl = std::make_unique<Impl>();
    impl->pid = *pid;
    impl->stdout_fd = fds[0];
    // Read lines until the ready line, the child's exit or the deadline.
    std::string pending;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(ready_timeout_ms);
    for (;;) {
        // Rounded up: truncated, the last fraction of a millisecond read as 0 left and the
        // child was declared silent up to 1 ms before its timeout (CI saw 299 of 300 ms).
        const auto left = std::chrono::ceil<std::chrono::milliseconds>(
                              deadline - std::chrono::steady_clock::now())
                              .count();
        if (left <= 0) {
            impl->stop(1000);
            return makeError("server process: not ready after " + std::to_string(ready_timeout_ms) +
                             " ms");
        }
        pollfd p{impl->stdout_fd, POLLIN, 0};
        if (poll(&p, 1, static_cast<int>(std::min<long long>(left, 100))) < 0 && errno != EINTR) {
            impl->stop(1000);
            return makeError(std::string("server process: poll: ") + std::strerror(errno));
        }
        if (p.revents & (POLLIN | POLLHUP)) {
            char buf[1024];
            const ssize_t n = read(impl->stdout_fd, buf, sizeof buf);
            if (n <= 0) {
                const int status = impl->stop(1000);
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
            const uint16_t port = portOfAddress(line.substr(at + kReadyPrefix.size()));
            if (port == 0) {
                impl->stop(1000);
                return makeError("server process: unreadable ready line: " + line);
            }
            impl->port = port;
            std::fflush(stdout);
            if (!pending.empty() && write(STDOUT_FILENO, pending.data(), pending.size()) < 0)
                pending.clear();
            fcntl(impl->stdout_fd, F_SETFL, fcntl(impl->stdout_fd, F_GETFL) | O_NONBLOCK);
            impl->startReader();
            return ServerProcess(std::move(impl));
        }
    }
}

ServerProcess::ServerProcess(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
ServerProcess::ServerProcess(ServerProcess&& other) noexcept = default;

ServerProcess& ServerProcess::operator=(ServerProcess&& other) noexcept {
    if (this != &other) {
        stop(1000);
        m_impl = std::move(other.m_impl);
    }
    return *this;
}

ServerProcess::~ServerProcess() {
    stop(1000);
}

uint16_t ServerProcess::port() const {
    return m_impl ? m_impl->port : 0;
}

pid_t ServerProcess::pid() const {
    return m_impl ? m_impl->pid : -1;
}

int ServerProcess::stop(int grace_ms) {
    return m_impl ? m_impl->stop(grace_ms) : -1;
}

}  // namespace qvr::runtime
