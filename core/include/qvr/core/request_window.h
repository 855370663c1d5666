// How many periphery requests a headset keeps outstanding. Shared by the runtime's headset
// (runtime/src/headset_client.cpp, step 3) and the simulator's model of it
// (sim/src/runtime_model.cpp), so that both withhold the same requests on the same arrivals.
#pragma once

#include <cstddef>

namespace qvr {

// A link slower than the headset's frames queues every periphery asked of it: on a 0.5 Mbit/s
// trace with a deep bottleneck buffer, a 5° periphery (9 KB) asked for every 26 ms built a 3 s
// queue in which nothing arrived within the wait limit, and no acknowledgement came back for 80
// frames to tell the controller why (docs/RUNTIME.md step 3). The headset asks for a frame's
// periphery only while fewer than window() requests are outstanding; a frame it does not ask
// for is shown with the newest periphery re-warped, at once (a late one waits the limit).
//
// A request is outstanding from when it is sent until its periphery has all come or failed, a
// later request's has all come (the server serves in order, so an older one still missing was
// dropped), or it is older than the wait limit while no media packet has come for a whole limit
// (the server or the link stopped, or the request was lost). A link that is delivering keeps
// every request it owes: an age limit alone let a 370 ms periphery's requests go after 1 s and
// the queue grow past the window (tests/runtime: ...QueuesNoMoreThanTheRequestWindow).
struct RequestWindow {
    // The frames in flight, each waiting on the remote chain, plus one late frame.
    static constexpr size_t window(size_t frames_in_flight) { return frames_in_flight + 1; }
    // Whether a request sent at request_ms still holds its place at now_ms, the newest media
    // packet having come at last_packet_ms (< 0: none yet).
    static constexpr bool holds(double request_ms, double now_ms, double last_packet_ms,
                                double wait_limit_ms) {
        const bool delivering = last_packet_ms >= 0.0 && now_ms - last_packet_ms < wait_limit_ms;
        return now_ms - request_ms < wait_limit_ms || delivering;
    }
};

}  // namespace qvr
