// What a runtime session leaves behind: the headset's telemetry.csv, trace.json and summary.json
// (`qvr client`), and the render server's counters, frames CSV and stamps file (`qvr server`),
// with the one-line summaries each command prints. summary.json's keys are spelled here once
// and reused by `qvr run`'s per-design entries (experiment/run_report.h).
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/runtime/chrome_trace.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/render_server.h"

namespace qvr::runtime {

// --- the headset -----------------------------------------------------------------------------

// A design's summary: the headline statistics (core's runStatsJson) with frames_displayed and
// frames_fallback_local.
nlohmann::json designSummaryJson(const DesignSummary& s);
// The transport counters every headset summary reports: lost and late streams, NACK and FEC
// recoveries, forged, replayed and dropped media.
nlohmann::json headsetCountersJson(const HeadsetStats& st);
// A trace.json's description: its path, events, and the server frames matched and clock offset.
nlohmann::json chromeTraceJson(const ChromeTraceInfo& t);

// One `qvr client` session as its summary.json names it.
struct ClientSession {
    std::string design;  // as given (e.g. "fixed:10")
    int frames_requested = 0;
    bool interrupted = false;
    double refresh_hz = 90.0;
};
nlohmann::json clientSummaryJson(const ClientSession& session, const HeadsetResult& result);

// Opens `path` as telemetry.csv, writes its header and makes `config` write each frame's row as
// the frame finishes, so a session of any length runs in flat memory.
Status startTelemetryCsv(const std::string& path, const std::string& design, std::ofstream& file,
                         HeadsetConfig& config);
// Closes the file started by startTelemetryCsv; an error when a row could not be written.
Status finishTelemetryCsv(const std::string& path, std::ofstream& file);

// Writes trace.json (the headset's stages and, from `stamps`, the server's) and summary.json
// into `out`.
Status writeClientOutputs(const std::filesystem::path& out, const ClientSession& session,
                          const HeadsetResult& result,
                          const std::vector<ServerFrameStamps>& stamps);

// The server's stamps for trace.json (`qvr server --stamps-csv`, a server on this machine), read
// after the session, when the server has stopped or flushed: a file that went bad meanwhile
// costs the server's rows on the timeline, not the session, and `error` says why they are
// missing. An empty path reads nothing.
struct ServerStampsRead {
    std::vector<ServerFrameStamps> stamps;
    std::string error;
};
ServerStampsRead readServerStampsAfterSession(const std::string& path);
// Why `path` is not a stamps file by its first line (empty when it is, or has no whole first
// line yet: the server writes it while the client runs).
std::string serverStampsHeaderError(const std::string& path);

// The line `qvr client` prints at the end, and the warnings it prints on stderr.
std::string clientReportLine(const HeadsetResult& result);
std::vector<std::string> clientWarnings(const HeadsetStats& st);

// --- the render server -----------------------------------------------------------------------

// The server's counters as --stats-json writes them (`qvr run` reads them back).
nlohmann::json serverStatsJson(const RenderServerStats& s, int core);
// One row per served frame: per-layer pixels, triangles, render, read-back, encode and send.
Status writeServerFramesCsv(const std::string& path, const std::vector<ServerFrameRecord>& records);

struct ServerOutputs {
    std::string stats_json;  // empty: not written
    std::string frames_csv;  // empty: not written
};
// Writes the outputs asked for once the server has stopped.
Status writeServerOutputs(const ServerOutputs& outputs, const RenderServerStats& s, int core,
                          const std::vector<ServerFrameRecord>& records);

// The two lines `qvr server` prints when it stops.
std::string serverStatsReport(const RenderServerStats& s);

// Per-frame stamps for timelines (qvr run's trace.json): one line per layer sent, on the
// server's steady clock, written by `config.on_frame` as each frame is sent and flushed whole
// frames at a time (a client on this machine reads the file while the server runs); bounded
// (kMaxServerStampLines) so a long-running server cannot fill the disk.
using StampsFile = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;
Status attachServerStampsCsv(const std::string& path, RenderServerConfig& config,
                             StampsFile& stamps);

}  // namespace qvr::runtime
