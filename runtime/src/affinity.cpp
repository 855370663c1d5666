// Core pinning through pthread_setaffinity_np.
#include "qvr/runtime/affinity.h"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <cstring>

#include <fmt/format.h>

namespace qvr::runtime {

int onlineCores() {
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? static_cast<int>(n) : 1;
}

Status pinCurrentThread(int core) {
    if (core < 0 || core >= CPU_SETSIZE)
        return makeError(fmt::format("core {} is out of range", core));
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(core, &set);
    const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    if (rc != 0)
        return makeError(fmt::format("cannot pin to core {}: {}", core, std::strerror(rc)));
    return {};
}

int currentCore() {
    return sched_getcpu();
}

ScopedThreadPin::ScopedThreadPin(int core) {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) == 0)
        for (int c = 0; c < CPU_SETSIZE; ++c)
            if (CPU_ISSET(c, &set))
                m_previous.push_back(c);
    if (Status st = pinCurrentThread(core); !st)
        m_error = st.error();
}

ScopedThreadPin::~ScopedThreadPin() {
    if (m_previous.empty())
        return;
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int c : m_previous)
        CPU_SET(c, &set);
    pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
}

}  // namespace qvr::runtime
