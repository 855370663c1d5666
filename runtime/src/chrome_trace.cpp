// trace.json in the Chrome trace-event format (chrome_trace.h).
#include "qvr/runtime/chrome_trace.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <tuple>

#include <fmt/format.h>

namespace qvr::runtime {

namespace {

constexpr int kTidDecision = 1, kTidFovea = 2, kTidRequest = 3, kTidUca = 4, kTidScanout = 5;
constexpr int kTidReceive = 10, kTidDecode = 20;  // + stream id
constexpr int kTidQueue = 1, kTidRender = 2, kTidEncode = 3, kTidSend = 4;
const char* const kStreamNames[kStreams] = {"left middle", "left outer", "right middle",
                                            "right outer"};

struct Key {
    int design;
    size_t frame;
};

// client_send_ns (the headset's pose sample, absolute) → the design and frame that sent it.
std::map<uint64_t, Key> requestIndex(const std::vector<TraceDesign>& designs) {
    std::map<uint64_t, Key> index;
    for (size_t d = 0; d < designs.size(); ++d)
        for (size_t i = 0; i < designs[d].frames->size(); ++i) {
            const FrameTelemetry& t = (*designs[d].frames)[i];
            if (t.remote_requested && t.pose_ns >= 0)
                index[static_cast<uint64_t>(designs[d].origin_ns + t.pose_ns)] = {int(d), i};
        }
    return index;
}

const FrameTelemetry* match(const std::map<uint64_t, Key>& index,
                            const std::vector<TraceDesign>& designs, const ServerFrameStamps& s,
                            int* design) {
    auto it = index.find(s.client_send_ns);
    if (it == index.end())
        return nullptr;
    const FrameTelemetry& t = (*designs[size_t(it->second.design)].frames)[it->second.frame];
    if (t.frame != int64_t(s.frame_id))
        return nullptr;
    *design = it->second.design;
    return &t;
}

class EventWriter {
public:
    explicit EventWriter(std::FILE* f) : m_f(f) { std::fputs("{\"traceEvents\":[\n", m_f); }
    void raw(const std::string& json) {
        std::fputs(m_first ? "" : ",\n", m_f);
        std::fputs(json.c_str(), m_f);
        m_first = false;
        ++m_events;
    }
    // A complete slice; times in ns on the headset clock relative to the design's start.
    void slice(int pid, int tid, const std::string& name, int64_t start_ns, int64_t end_ns,
               int64_t frame) {
        if (start_ns < 0 || end_ns < start_ns)
            return;
        raw(fmt::format(
            R"({{"ph":"X","pid":{},"tid":{},"name":"{}","ts":{:.3f},"dur":{:.3f},"args":{{"frame":{}}}}})",
            pid, tid, name, start_ns * 1e-3, (end_ns - start_ns) * 1e-3, frame));
    }
    void flow(char ph, int pid, int tid, int64_t id, int64_t ts_ns) {
        raw(fmt::format(
            R"({{"ph":"{}","pid":{},"tid":{},"name":"frame","cat":"frame","id":{},"ts":{:.3f}{}}})",
            ph, pid, tid, id, ts_ns * 1e-3, ph == 'f' ? R"(,"bp":"e")" : ""));
    }
    void name(const char* what, int pid, int tid, const std::string& n) {
        raw(fmt::format(R"({{"ph":"M","pid":{},"tid":{},"name":"{}","args":{{"name":"{}"}}}})", pid,
                        tid, what, n));
    }
    void sortIndex(int pid, int tid, int index) {
        raw(fmt::format(
            R"({{"ph":"M","pid":{},"tid":{},"name":"thread_sort_index","args":{{"sort_index":{}}}}})",
            pid, tid, index));
    }
    int64_t events() const { return m_events; }

private:
    std::FILE* m_f;
    bool m_first = true;
    int64_t m_events = 0;
};

bool parseU64(const std::string& s, uint64_t& v) {
    const char* end = s.data() + s.size();
    auto r = std::from_chars(s.data(), end, v);
    return r.ec == std::errc() && r.ptr == end;
}

}  // namespace

Expected<std::vector<ServerFrameStamps>> readServerStamps(const std::string& path) {
    std::ifstream in(path);
    if (!in)
        return makeError(fmt::format("cannot read server stamps '{}'", path));
    std::string line;
    if (!std::getline(in, line) || line + "\n" != kServerStampsHeader)
        return makeError(fmt::format("{}:1: not a server stamps file (header)", path));
    std::vector<ServerFrameStamps> out;
    std::map<std::tuple<uint64_t, uint32_t, uint64_t>, size_t> index;
    for (int line_no = 2; std::getline(in, line); ++line_no) {
        constexpr size_t kCells = 13;
        constexpr size_t kFragments = kCells - 1;  // -1: the renderer counted none
        uint64_t v[kCells];
        bool uncounted = false;
        size_t pos = 0, n = 0;
        bool ended = false;  // the last cell was the line's last
        while (n < kCells) {
            const size_t comma = line.find(',', pos);
            const std::string cell =
                line.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
            // Client ids are any 64-bit value; times and counts must fit the signed clock.
            if (n == kFragments && cell == "-1") {
                uncounted = true;
                v[n] = 0;
            } else if (!parseU64(cell, v[n]) ||
                       (n != 0 && v[n] > uint64_t(std::numeric_limits<int64_t>::max())))
                break;
            ++n;
            if (comma == std::string::npos) {
                ended = true;
                break;
            }
            pos = comma + 1;
        }
        if (n != kCells || !ended || v[1] > std::numeric_limits<uint32_t>::max() ||
            v[6] >= kStreams)
            return makeError(fmt::format("{}:{}: malformed server stamps line", path, line_no));
        const auto key = std::make_tuple(uint64_t(v[0]), uint32_t(v[1]), uint64_t(v[2]));
        auto [it, added] = index.try_emplace(key, out.size());
        if (added) {
            ServerFrameStamps s;
            s.client = uint64_t(v[0]);
            s.frame_id = uint32_t(v[1]);
            s.client_send_ns = uint64_t(v[2]);
            s.queued_ns = int64_t(v[3]);
            s.start_ns = int64_t(v[4]);
            s.end_ns = int64_t(v[5]);
            out.push_back(std::move(s));
        }
        out[it->second].layers.push_back({uint8_t(v[6]), int64_t(v[7]), int64_t(v[8]),
                                          int64_t(v[9]), int64_t(v[10]), int64_t(v[11]),
                                          uncounted ? -1 : int64_t(v[kFragments])});
    }
    return out;
}

ClockOffset estimateClockOffset(const std::vector<TraceDesign>& designs,
                                const std::vector<ServerFrameStamps>& server) {
    const auto index = requestIndex(designs);
    int64_t min_up = std::numeric_limits<int64_t>::max();
    int64_t min_down = std::numeric_limits<int64_t>::max();
    ClockOffset c;
    for (const ServerFrameStamps& s : server) {
        int d = 0;
        const FrameTelemetry* t = match(index, designs, s, &d);
        if (!t)
            continue;
        // The request left after the decision (request_ns is stamped after the send returns,
        // too late for a bound).
        const int64_t origin = designs[size_t(d)].origin_ns;
        const int64_t left_ns = t->decision_ns >= 0 ? t->decision_ns : t->pose_ns;
        min_up = std::min(min_up, s.queued_ns - (origin + left_ns));
        for (const ServerFrameStamps::Layer& l : s.layers)
            if (t->stream_rx_ns[l.stream_id] >= 0)
                min_down = std::min(min_down, origin + t->stream_rx_ns[l.stream_id] - l.sent_ns);
        ++c.requests;
    }
    if (c.requests == 0 || min_down == std::numeric_limits<int64_t>::max())
        return {};
    c.offset_ns = 0.5 * double(min_up - min_down);
    c.bound_ns = 0.5 * double(min_up + min_down);
    return c;
}

std::vector<ServerBusy> serverBusyPerDesign(const std::vector<TraceDesign>& designs,
                                            const std::vector<ServerFrameStamps>& server) {
    std::vector<ServerBusy> out(designs.size());
    const auto index = requestIndex(designs);
    for (const ServerFrameStamps& s : server) {
        int d = 0;
        if (!match(index, designs, s, &d))
            continue;
        ServerBusy& b = out[size_t(d)];
        double ms = 0.0;
        for (const ServerFrameStamps::Layer& l : s.layers) {
            ms += double(std::max<int64_t>(0, l.encode_end_ns - l.render_start_ns)) * 1e-6;
            // match() found the design's own frame of that id: the index is bounded by its run.
            if (l.pixels <= 0 || l.fragments < 0)
                continue;
            if (b.fragments_per_px.size() <= s.frame_id)
                b.fragments_per_px.resize(size_t(s.frame_id) + 1, {-1.0, -1.0, -1.0, -1.0});
            b.fragments_per_px[s.frame_id][l.stream_id] = double(l.fragments) / double(l.pixels);
        }
        ++b.frames;
        b.busy_ms_mean += (ms - b.busy_ms_mean) / double(b.frames);
    }
    return out;
}

Expected<ChromeTraceInfo> writeChromeTrace(const std::string& path,
                                           const std::vector<TraceDesign>& designs,
                                           const std::vector<ServerFrameStamps>& server,
                                           int max_frames_per_design) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "w"), std::fclose);
    if (!f)
        return makeError(fmt::format("cannot write '{}'", path));
    ChromeTraceInfo info;
    info.offset = estimateClockOffset(designs, server);
    const int64_t offset_ns = std::llround(info.offset.offset_ns);
    EventWriter w(f.get());
    for (size_t d = 0; d < designs.size(); ++d) {
        const TraceDesign& td = designs[d];
        const int hp = 2 * int(d) + 1, sp = 2 * int(d) + 2;
        w.name("process_name", hp, 0, td.name + ": headset");
        w.name("process_name", sp, 0, td.name + ": server");
        const std::pair<int, std::string> headset_tracks[] = {{kTidDecision, "pose + decision"},
                                                              {kTidFovea, "fovea / local render"},
                                                              {kTidRequest, "request"},
                                                              {kTidUca, "UCA"},
                                                              {kTidScanout, "scan-out"}};
        int order = 0;
        for (const auto& [tid, n] : headset_tracks) {
            w.name("thread_name", hp, tid, n);
            w.sortIndex(hp, tid, tid == kTidUca || tid == kTidScanout ? 100 + order++ : order++);
        }
        for (int s = 0; s < kStreams; ++s) {
            w.name("thread_name", hp, kTidReceive + s, fmt::format("receive {}", kStreamNames[s]));
            w.name("thread_name", hp, kTidDecode + s, fmt::format("decode {}", kStreamNames[s]));
            w.sortIndex(hp, kTidReceive + s, 10 + 2 * s);
            w.sortIndex(hp, kTidDecode + s, 11 + 2 * s);
        }
        for (const auto& [tid, n] : {std::pair<int, const char*>{kTidQueue, "queue"},
                                     {kTidRender, "render"},
                                     {kTidEncode, "encode"},
                                     {kTidSend, "send"}}) {
            w.name("thread_name", sp, tid, n);
            w.sortIndex(sp, tid, tid);
        }
        const int64_t frame_ns = std::llround(1e9 / std::max(td.refresh_hz, 1.0));
        size_t written = 0;
        for (const FrameTelemetry& t : *td.frames) {
            if (written >= size_t(max_frames_per_design)) {
                ++info.frames_left_out;
                continue;
            }
            ++written;
            const int64_t k = t.frame;
            w.slice(hp, kTidDecision, fmt::format("decide {}", k), t.pose_ns, t.decision_ns, k);
            w.slice(hp, kTidFovea, fmt::format("render {}", k), t.local_start_ns, t.local_end_ns,
                    k);
            w.slice(hp, kTidUca, fmt::format("UCA {}", k), t.uca_start_ns, t.uca_end_ns, k);
            w.slice(hp, kTidScanout, fmt::format("scan-out {}", k), t.display_ns,
                    t.display_ns + frame_ns, k);
            for (int s = 0; s < kStreams; ++s)
                w.slice(hp, kTidDecode + s, fmt::format("decode {}", k), t.stream_rx_ns[size_t(s)],
                        t.stream_decoded_ns[size_t(s)], k);
            const int64_t id = int64_t(d) * 10'000'000 + k;
            const bool requested = t.remote_requested && t.request_ns >= 0;
            if (requested) {
                // A short slice for the arrow to leave from.
                // From the decision to the send call's return: building and sending it.
                const int64_t from_ns = t.decision_ns >= 0 ? t.decision_ns : t.pose_ns;
                w.slice(hp, kTidRequest, fmt::format("request {}", k), from_ns,
                        std::max(t.request_ns, from_ns + 1000), k);
                w.flow('s', hp, kTidRequest, id, from_ns);
            } else if (t.pose_ns >= 0 && t.decision_ns >= 0) {
                w.flow('s', hp, kTidDecision, id, t.pose_ns);
            }
            if (t.display_ns >= 0)
                w.flow('f', hp, kTidScanout, id, t.display_ns);
            ++info.frames_written;
        }
    }
    // The server's frames, on the headset clock of the design whose request they served.
    const auto index = requestIndex(designs);
    for (const ServerFrameStamps& s : server) {
        int d = 0;
        const FrameTelemetry* t = match(index, designs, s, &d);
        if (!t || t->frame >= max_frames_per_design)
            continue;
        ++info.server_frames_matched;
        const int sp = 2 * d + 2;
        const int64_t shift = -offset_ns - designs[size_t(d)].origin_ns;
        const int64_t k = t->frame;
        w.slice(sp, kTidQueue, fmt::format("queued {}", k), s.queued_ns + shift, s.start_ns + shift,
                k);
        int64_t last_render_start = -1;
        for (const ServerFrameStamps::Layer& l : s.layers) {
            const char* sn = kStreamNames[l.stream_id];
            if (l.render_start_ns !=
                last_render_start)  // one-pass periphery: one render, two layers
                w.slice(sp, kTidRender, fmt::format("render {} {}", k, sn),
                        l.render_start_ns + shift, l.render_end_ns + shift, k);
            last_render_start = l.render_start_ns;
            w.slice(sp, kTidEncode, fmt::format("encode {} {}", k, sn), l.render_end_ns + shift,
                    l.encode_end_ns + shift, k);
            w.slice(sp, kTidSend, fmt::format("send {} {}", k, sn), l.encode_end_ns + shift,
                    l.sent_ns + shift, k);
            // Receive: from the server's send to the last packet's arrival on the headset.
            if (t->stream_rx_ns[l.stream_id] >= 0)
                w.slice(2 * d + 1, kTidReceive + l.stream_id, fmt::format("receive {}", k),
                        l.sent_ns + shift, t->stream_rx_ns[l.stream_id], k);
        }
    }
    w.raw(fmt::format(
        "{{\"ph\":\"M\",\"pid\":0,\"tid\":0,\"name\":\"process_name\",\"args\":{{\"name\":"
        "\"clock: headset steady clock, 0 = each design's start; server stamps shifted by "
        "{:.3f} ms (estimated, +- {:.3f} ms, from {} requests)\"}}}}",
        -info.offset.offset_ns * 1e-6, info.offset.bound_ns * 1e-6, info.offset.requests));
    std::fprintf(f.get(),
                 "\n],\"displayTimeUnit\":\"ms\",\"otherData\":{\"clock\":\"headset steady clock, "
                 "ns/1000 from each design's start\",\"server_offset_ns\":%.0f,"
                 "\"server_offset_bound_ns\":%.0f,\"offset_requests\":%lld,"
                 "\"frames_left_out\":%lld}}\n",
                 info.offset.offset_ns, info.offset.bound_ns,
                 static_cast<long long>(info.offset.requests),
                 static_cast<long long>(info.frames_left_out));
    info.events = w.events();
    if (std::fflush(f.get()) != 0 || std::ferror(f.get()))
        return makeError(fmt::format("error writing '{}'", path));
    return info;
}

}  // namespace qvr::runtime
