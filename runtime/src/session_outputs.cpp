// The files and summaries a runtime session writes (session_outputs.h).
#include "qvr/runtime/session_outputs.h"

#include <fmt/format.h>

#include "qvr/core/run_summary_json.h"
#include "qvr/core/text_file.h"

namespace qvr::runtime {

nlohmann::json designSummaryJson(const DesignSummary& s) {
    nlohmann::json j = runStatsJson(s);
    j["frames_displayed"] = s.frames_displayed;
    j["frames_fallback_local"] = s.frames_fallback_local;
    return j;
}

nlohmann::json headsetCountersJson(const HeadsetStats& st) {
    return {{"streams_lost", st.streams_lost},
            {"late_frames", st.late_frames},
            {"requests_withheld", st.requests_withheld},
            {"nacks_sent", st.net.assembler.nacks},
            {"packets_recovered", st.net.assembler.packets_recovered},
            {"fec_recoveries", st.net.assembler.fec_recoveries},
            {"fec_packets_recovered", st.net.assembler.fec_packets_recovered},
            {"media_drops", st.net.media_drops.total()},
            {"media_forged", st.net.media_drops[net::WireError::kBadMac]},
            {"media_replayed", st.net.media_drops[net::WireError::kReplayed]}};
}

nlohmann::json chromeTraceJson(const ChromeTraceInfo& t) {
    return {{"path", "trace.json"},
            {"events", t.events},
            {"server_frames", t.server_frames_matched},
            {"server_offset_ms", t.offset.offset_ns * 1e-6},
            {"server_offset_bound_ms", t.offset.bound_ns * 1e-6}};
}

nlohmann::json clientSummaryJson(const ClientSession& session, const HeadsetResult& result) {
    const HeadsetStats& st = result.stats;
    nlohmann::json j = designSummaryJson(result.summary);
    j.update(headsetCountersJson(st));
    j.update({{"design", result.summary.design},
              {"frames_requested", session.frames_requested},
              // telemetry.csv's times are ns after this steady-clock (CLOCK_MONOTONIC) instant,
              // so other tools can place their own events on its timeline
              {"clock_origin_ns", result.origin_ns},
              {"interrupted", session.interrupted},
              {"connects", st.connects},
              {"connect_failures", st.connect_failures},
              {"server_proof_failures", st.net.server_proof_failures},
              {"incompatible_refusals", st.net.incompatible_refusals},
              {"capacity_refusals", st.net.capacity_refusals},
              {"control_drops", st.net.control_drops.total()},
              {"control_forged", st.net.control_forged},
              {"control_replayed", st.net.control_replayed},
              {"key_frame_requests", st.key_frame_requests},
              {"packets_nacked", st.net.assembler.packets_nacked},
              {"fec_parity_received", st.net.assembler.fec_parity_received},
              {"fec_parity_unused", st.net.assembler.fec_parity_unused},
              {"keepalives_sent", st.net.keepalives_sent},
              {"silent_server_frames", st.silent_server_frames}});
    return j;
}

Status startTelemetryCsv(const std::string& path, const std::string& design, std::ofstream& file,
                         HeadsetConfig& config) {
    file.open(path);
    if (!file)
        return makeError("cannot write '" + path + "'");
    file << telemetryCsvHeader();
    config.frame_sink = [&file, design](const FrameTelemetry& t) {
        file << telemetryCsvRow(design, t);
    };
    return {};
}

Status finishTelemetryCsv(const std::string& path, std::ofstream& file) {
    file.close();
    if (!file)
        return makeError("error writing '" + path + "'");
    return {};
}

Status writeClientOutputs(const std::filesystem::path& out, const ClientSession& session,
                          const HeadsetResult& result,
                          const std::vector<ServerFrameStamps>& stamps) {
    auto trace = writeChromeTrace(
        (out / "trace.json").string(),
        {{session.design, result.origin_ns, session.refresh_hz, &result.frames}}, stamps);
    if (!trace)
        return makeError(trace.error());
    nlohmann::json j = clientSummaryJson(session, result);
    j["trace"] = chromeTraceJson(*trace);
    j["trace"]["frames"] = result.frames.size();
    j["trace"]["first_frame"] = result.frames.empty() ? 0 : result.frames.front().frame;
    return writeJsonFile((out / "summary.json").string(), j);
}

ServerStampsRead readServerStampsAfterSession(const std::string& path) {
    ServerStampsRead read;
    if (path.empty())
        return read;
    auto stamps = readServerStamps(path);
    if (stamps)
        read.stamps = std::move(*stamps);
    else
        read.error = stamps.error();
    return read;
}

std::string serverStampsHeaderError(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    if (std::getline(in, line) && !in.eof() && line + "\n" != kServerStampsHeader)
        return "'" + path + "' is not a server stamps file (qvr server --stamps-csv): its header";
    return {};
}

std::string clientReportLine(const HeadsetResult& result) {
    const DesignSummary& s = result.summary;
    const HeadsetStats& st = result.stats;
    return fmt::format(
        "qvr client: {} fps {:.1f}, MTP {:.1f} ms (p99 {:.1f}), {:.0f} B/frame, e1 {:.1f} deg, "
        "{} displayed, {} reused, {} local fallback; {} connects, {} failed\n",
        s.design, s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean, s.e1_deg_mean,
        s.frames_displayed, s.frames_reused, s.frames_fallback_local, st.connects,
        st.connect_failures);
}

std::vector<std::string> clientWarnings(const HeadsetStats& st) {
    std::vector<std::string> warnings;
    if (st.connects == 0 && st.net.server_proof_failures > 0)
        warnings.emplace_back("the server did not prove the pre-shared key");
    if (st.net.control_forged + st.net.control_replayed > 0)
        warnings.push_back(
            fmt::format("{} forged and {} replayed control messages ended "
                        "connections",
                        st.net.control_forged, st.net.control_replayed));
    return warnings;
}

nlohmann::json serverStatsJson(const RenderServerStats& s, int core) {
    const net::ServerStats& n = s.net;
    return {{"requests", s.requests},
            {"requests_dropped", s.requests_dropped},
            {"requests_invalid", s.requests_invalid},
            {"frames_rendered", s.frames_rendered},
            {"layers_rendered", s.layers_rendered},
            {"periphery_passes", s.periphery_passes},
            {"streams_sent", s.streams_sent},
            {"stream_send_failures", s.stream_send_failures},
            {"render_failures", s.render_failures},
            {"encode_failures", s.encode_failures},
            {"key_frame_requests", s.key_frame_requests},
            {"render_ms_total", s.render_ms_total},
            {"encode_ms_total", s.encode_ms_total},
            {"readback_ms_total", s.readback_ms_total},
            {"send_ms_total", s.send_ms_total},
            {"connections", n.connections},
            {"clients_accepted", n.clients_accepted},
            {"auth_failures", n.auth_failures},
            {"handshake_timeouts", n.handshake_timeouts},
            {"refused_full", n.refused_full},
            {"pending_evicted", n.pending_evicted},
            {"idle_timeouts", n.idle_timeouts},
            {"keepalives", n.keepalives},
            {"protocol_errors", n.protocol_errors},
            {"version_mismatches", n.version_mismatches},
            {"settings_refusals", n.settings_refusals},
            {"route_failures", n.route_failures},
            {"control_forged", n.control_forged},
            {"control_replayed", n.control_replayed},
            {"nacks", n.nacks},
            {"packets_retransmitted", n.packets_retransmitted},
            {"bytes_retransmitted", n.bytes_retransmitted},
            {"retransmissions_refused", n.retransmissions_refused},
            {"fec_frames", n.fec_frames},
            {"fec_parity_packets", n.fec_parity_packets},
            {"fec_parity_bytes", n.fec_parity_bytes},
            {"client_loss_ppm", n.client_loss_ppm},
            {"control_drops", n.control_drops.total()},
            {"link",
             {{"packets_in", n.link.packets_in},
              {"packets_delivered", n.link.packets_delivered},
              {"dropped_loss", n.link.dropped_loss},
              {"dropped_queue", n.link.dropped_queue},
              {"dropped_burst", n.link.dropped_burst},
              {"reordered", n.link.reordered},
              {"duplicated", n.link.duplicated},
              {"spiked", n.link.spiked}}},
            {"core", core}};
}

Status writeServerFramesCsv(const std::string& path,
                            const std::vector<ServerFrameRecord>& records) {
    std::ofstream f(path);
    f << "client,frame,e1_deg,received_ns,start_ns,done_ns";
    for (int sid = 0; sid < 4; ++sid)
        f << fmt::format(
            ",pixels{0},triangles{0},render_ms{0},readback_ms{0},encode_ms{0},"
            "send_ms{0},bytes{0},fragments{0}",
            sid);
    f << "\n";
    for (const ServerFrameRecord& r : records) {
        f << fmt::format("{},{},{:.3f},{},{},{}", r.client, r.frame_id, r.e1_deg, r.received_ns,
                         r.start_ns, r.done_ns);
        for (size_t sid = 0; sid < 4; ++sid)
            f << fmt::format(",{},{},{:.3f},{:.3f},{:.3f},{:.3f},{},{}", r.pixels[sid],
                             r.triangles[sid], r.render_ms[sid], r.readback_ms[sid],
                             r.encode_ms[sid], r.send_ms[sid], r.bytes[sid], r.fragments[sid]);
        f << "\n";
    }
    if (!f)
        return makeError("cannot write '" + path + "'");
    return {};
}

Status writeServerOutputs(const ServerOutputs& outputs, const RenderServerStats& s, int core,
                          const std::vector<ServerFrameRecord>& records) {
    if (!outputs.stats_json.empty()) {
        nlohmann::json j = serverStatsJson(s, core);
        j.update(serverPoolJson(s));  // "workers", "admission", "sessions"
        if (Status st = writeJsonFile(outputs.stats_json, j); !st)
            return st;
    }
    if (!outputs.frames_csv.empty())
        return writeServerFramesCsv(outputs.frames_csv, records);
    return {};
}

std::string serverStatsReport(const RenderServerStats& s) {
    const net::ServerStats& n = s.net;
    return fmt::format(
               "qvr server: {} requests ({} dropped, {} invalid), {} frames, {} streams sent, {} "
               "auth failures, {} malformed control messages\n",
               s.requests, s.requests_dropped, s.requests_invalid, s.frames_rendered,
               s.streams_sent, n.auth_failures, n.control_drops.total()) +
           fmt::format(
               "qvr server: {} connections, {} sessions; {} handshake timeouts, {} idle "
               "timeouts, {} evicted, {} refused full, {} protocol errors, {} version / {} "
               "settings refusals, {} media ports unverified; {} forged / {} replayed control "
               "messages; {} NACKs, {} packets retransmitted\n",
               n.connections, n.clients_accepted, n.handshake_timeouts, n.idle_timeouts,
               n.pending_evicted, n.refused_full, n.protocol_errors, n.version_mismatches,
               n.settings_refusals, n.route_failures, n.control_forged, n.control_replayed, n.nacks,
               n.packets_retransmitted);
}

Status attachServerStampsCsv(const std::string& path, RenderServerConfig& config,
                             StampsFile& stamps) {
    stamps.reset(std::fopen(path.c_str(), "w"));
    if (!stamps)
        return makeError("cannot write '" + path + "'");
    std::fputs(kServerStampsHeader, stamps.get());
    config.on_frame = [f = stamps.get(), lines = int64_t{0}](const ServerFrameStamps& st) mutable {
        for (const ServerFrameStamps::Layer& l : st.layers) {
            if (++lines > kMaxServerStampLines)
                return;
            fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{},{},{}\n", st.client, st.frame_id,
                       st.client_send_ns, st.queued_ns, st.start_ns, st.end_ns, l.stream_id,
                       l.render_start_ns, l.render_end_ns, l.encode_end_ns, l.sent_ns, l.pixels,
                       l.fragments);
        }
        // Whole frames on disk: a client on this machine reads the file while we run.
        std::fflush(f);
    };
    return {};
}

}  // namespace qvr::runtime
