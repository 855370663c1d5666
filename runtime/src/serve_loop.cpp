// A server process's serving loop and its Agones lifecycle (serve_loop.h).
#include "qvr/runtime/serve_loop.h"

#include <chrono>
#include <thread>

namespace qvr::runtime {

Expected<net::AgonesSdkOptions> agonesSdkOptions(const char* port_env) {
    auto port = net::agonesHttpPort(port_env);
    if (!port)
        return makeError("--agones: " + port.error());
    net::AgonesSdkOptions options;
    options.port = *port;
    return options;
}

namespace {

void waitUntilStopped(const std::atomic<bool>& stop, double duration_s) {
    const auto t0 = std::chrono::steady_clock::now();
    while (!stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (duration_s > 0 &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >
                duration_s)
            break;
    }
}

}  // namespace

Status serveUntilStopped(const std::atomic<bool>& stop, double duration_s, net::AgonesSdk* sdk,
                         const ServeEvents& events) {
    if (!sdk) {
        waitUntilStopped(stop, duration_s);
        return Status::success();
    }
    if (Status st = sdk->ready(); !st)
        return st;
    if (events.ready_sent)
        events.ready_sent(sdk->options().port);
    {
        net::AgonesHealthPinger pinger(*sdk, kAgonesHealthPeriodMs);
        waitUntilStopped(stop, duration_s);
    }
    if (Status st = sdk->shutdown(); !st && events.shutdown_failed)
        events.shutdown_failed(st.error());
    return Status::success();
}

}  // namespace qvr::runtime
