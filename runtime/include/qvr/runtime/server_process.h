// The render server in a process of its own, as `qvr run` starts it. One process for both sides
// would share Mesa's llvmpipe screen — and with it one set of rasterizer threads, created by
// whichever side made the first GL context and pinned to that side's core — so the headset would
// rasterize on the server's core (or the other way round). Two processes give each side its own
// GL stack on its own core, as two machines would.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr::runtime {

class ServerProcess {
public:
    // Starts `executable` with `args` (e.g. {"server", "--port", "0", …}) and waits up to
    // `ready_timeout_ms` for the line "qvr server: listening on HOST:PORT" on its standard
    // output; its other output, before and after that line, is passed through to ours (after it
    // by a thread, so a chatty child never blocks on a full pipe). Errors when it exits, stays
    // silent or prints a ready line without a port.
    static Expected<ServerProcess> start(const std::string& executable,
                                         const std::vector<std::string>& args,
                                         int ready_timeout_ms = 30000);
    ServerProcess(ServerProcess&& other) noexcept;
    ServerProcess& operator=(ServerProcess&& other) noexcept;
    ServerProcess(const ServerProcess&) = delete;
    ServerProcess& operator=(const ServerProcess&) = delete;
    ~ServerProcess();

    uint16_t port() const;
    pid_t pid() const;
    // SIGTERM, then SIGKILL after `grace_ms`; returns the exit status (128 + signal if killed),
    // -1 when there is no child. Never waits on the child's descendants.
    int stop(int grace_ms = 5000);

    struct Impl;

private:
    explicit ServerProcess(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

// The path of the running executable (/proc/self/exe).
Expected<std::string> selfExecutable();

// Starts argv[0] with the arguments argv and this process's environment; its standard input and
// output are dup'ed from stdin_fd and stdout_fd where those are not -1. The child's pid, or the
// reason it did not start (strerror's text).
Expected<pid_t> spawnProcess(std::vector<std::string> argv, int stdin_fd, int stdout_fd);

}  // namespace qvr::runtime
