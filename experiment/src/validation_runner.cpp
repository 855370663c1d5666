// The correlation sheet's children as processes (validation.h ProcessRunner). The signal
// handlers pass SIGINT/SIGTERM to the child under way rather than ignoring them for its
// duration (as std::system does), so that one Ctrl-C stops the sheet and no child is orphaned.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <fstream>

#include "qvr/experiment/validation.h"

namespace qvr::experiment {

namespace {

std::atomic<pid_t> g_child{0};
volatile std::sig_atomic_t g_stop = 0;
static_assert(std::atomic<pid_t>::is_always_lock_free);

void onSignal(int sig) {
    g_stop = sig;
    if (const pid_t c = g_child.load(); c > 0)
        ::kill(c, sig);
}

// Runs `line` through /bin/sh (exec'd, so the shell's child is the command itself and the
// signal reaches it), stdin from /dev/null.
int runShell(const std::string& line) {
    const std::string exec_line = "exec " + line + " < /dev/null";
    const pid_t pid = ::fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        ::execl("/bin/sh", "sh", "-c", exec_line.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    g_child.store(pid);
    if (g_stop != 0)  // a signal between the fork and the store
        ::kill(pid, g_stop);
    int st = 0;
    pid_t w;
    do {
        w = ::waitpid(pid, &st, 0);
    } while (w < 0 && errno == EINTR);
    g_child.store(0);
    if (w < 0)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
}

}  // namespace

ProcessRunner::ProcessRunner() {
    g_stop = 0;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
}

ProcessRunner::~ProcessRunner() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}

ChildOutcome ProcessRunner::run(const ChildCommand& command) {
    ChildOutcome outcome;
    outcome.exit_code = runShell(command.line);
    if (outcome.exit_code == 0) {
        std::ifstream f(command.result_path);
        outcome.result = nlohmann::json::parse(f, nullptr, false);
    }
    return outcome;
}

int ProcessRunner::stopSignal() const {
    return g_stop;
}

}  // namespace qvr::experiment
