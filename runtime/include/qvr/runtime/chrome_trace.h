// A run's timeline in the Chrome trace-event format (trace.json; opens in ui.perfetto.dev and
// chrome://tracing): per design, one track per headset stage (decision, fovea render, request,
// each stream's receive and decode, UCA, scan-out) and per server stage (queue, render, encode,
// send), with each frame as a flow arrow from its request to its display. The server's stamps
// come from its own file (qvr server --stamps-csv) on its steady clock and are put on the
// headset's clock with an offset estimated from the request and stream round trips.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/telemetry.h"

namespace qvr::runtime {

inline constexpr const char* kServerStampsHeader =
    "client,frame_id,client_send_ns,queued_ns,start_ns,end_ns,stream,render_start_ns,"
    "render_end_ns,encode_end_ns,sent_ns,pixels,fragments\n";
// A server keeps writing stamps for at most this many layers (about 30 MB).
inline constexpr int64_t kMaxServerStampLines = 300000;

// The stamps file, one ServerFrameStamps per (client, frame id, client send time). A malformed
// line is an error naming the line.
Expected<std::vector<ServerFrameStamps>> readServerStamps(const std::string& path);

struct TraceDesign {
    std::string name;
    int64_t origin_ns = 0;  // the headset's steady clock at the design's start (telemetry's 0)
    double refresh_hz = 90.0;
    const std::vector<FrameTelemetry>* frames = nullptr;
};

// Server clock minus headset clock. Each matched request gives d_up = queued − decision (offset
// plus uplink; the request leaves after the decision) and each stream d_down = received − sent
// (downlink minus offset, sent stamped before the transport has it); the estimate is
// (min d_up − min d_down) / 2, good to ± (min d_up + min d_down) / 2.
struct ClockOffset {
    double offset_ns = 0.0;
    double bound_ns = 0.0;
    int64_t requests = 0;  // matched requests it was estimated from
};
ClockOffset estimateClockOffset(const std::vector<TraceDesign>& designs,
                                const std::vector<ServerFrameStamps>& server);

// The server's work for each design, as the simulator's server_busy_ms counts it: per matched
// server frame, the sum over its layers of render, readback and encode (render start to encode
// end; not the queue, not the send). One entry per design, in the order given.
struct ServerBusy {
    int64_t frames = 0;
    double busy_ms_mean = 0.0;
    // By frame id, per stream: the fragments the layer's render shaded per layer pixel (its
    // overdraw, which the server's render law charges, docs/MODEL.md §9); < 0: not counted.
    std::vector<std::array<double, 4>> fragments_per_px;
};
std::vector<ServerBusy> serverBusyPerDesign(const std::vector<TraceDesign>& designs,
                                            const std::vector<ServerFrameStamps>& server);

struct ChromeTraceInfo {
    int64_t events = 0;
    int64_t frames_written = 0;
    int64_t frames_left_out = 0;  // beyond max_frames_per_design
    int64_t server_frames_matched = 0;
    ClockOffset offset;
};
// Writes at most max_frames_per_design frames of each design (the first ones), so a long run's
// timeline stays loadable (~20 events, ~2 KB per frame).
Expected<ChromeTraceInfo> writeChromeTrace(const std::string& path,
                                           const std::vector<TraceDesign>& designs,
                                           const std::vector<ServerFrameStamps>& server,
                                           int max_frames_per_design = 3000);

}  // namespace qvr::runtime
