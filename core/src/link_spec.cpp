// The link grammar (link_spec.h): a profile, then key=value options, each checked for range.
#include "qvr/core/link_spec.h"

#include <charconv>
#include <cmath>
#include <string_view>

namespace qvr {
namespace {

bool parseDouble(std::string_view s, double& out) {
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && p == s.data() + s.size() && std::isfinite(out);
}

// "A:B:C" into up to `n` numbers; false unless there are between min_n and n of them.
bool parseList(std::string_view s, size_t min_n, size_t n, double* out) {
    size_t i = 0;
    while (true) {
        const size_t colon = s.find(':');
        if (i == n || !parseDouble(s.substr(0, colon), out[i])) {
            return false;
        }
        ++i;
        if (colon == std::string_view::npos) {
            break;
        }
        s.remove_prefix(colon + 1);
    }
    return i >= min_n;
}

bool parseU64(std::string_view s, uint64_t& out) {
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && p == s.data() + s.size();
}

// Below 1 kbit/s a full queue (up to 1 GiB) would take longer than int64 nanoseconds can count.
constexpr double kMinLinkMbps = 0.001;
constexpr double kMaxLinkMbps = 1e6;

bool parseMbps(std::string_view s, double& bps) {
    double mbps = 0;
    if (!parseDouble(s, mbps) || mbps < kMinLinkMbps || mbps > kMaxLinkMbps)
        return false;
    bps = mbps * 1e6;
    return true;
}

Status parseProfile(const std::string& spec, std::string_view profile, LinkSpec& c) {
    c.name = std::string(profile);
    c.profile = c.name;
    if (profile == "none") {
    } else if (profile == "wifi") {
        c.rate_bps = 200e6;
    } else if (profile == "lte" || profile == "4g") {
        c.profile = "lte";
        c.rate_bps = 100e6;
    } else if (profile == "5g") {
        c.rate_bps = 500e6;
    } else if (profile.starts_with("rate:")) {
        c.profile = "rate";
        if (!parseMbps(profile.substr(5), c.rate_bps))
            return makeError("link '" + spec +
                             "': rate:MBPS needs a rate in [0.001, 1e6] Mbit/s (slower rates "
                             "would hold a packet for longer than the clock can count)");
    } else if (profile.starts_with("trace:")) {
        c.profile = "trace";
        std::string_view path = profile.substr(6);
        if (const size_t at = path.rfind('@'); at != std::string_view::npos) {
            if (!parseMbps(path.substr(at + 1), c.trace_target_bps))
                return makeError("link '" + spec +
                                 "': trace:PATH@MBPS needs a mean in [0.001, 1e6] Mbit/s");
            path = path.substr(0, at);
        }
        if (path.empty())
            return makeError("link '" + spec + "': trace:PATH[@MBPS] needs a path");
        c.trace_path = std::string(path);
    } else {
        return makeError("link '" + spec + "': unknown network profile '" + std::string(profile) +
                         "' (none, wifi, lte or 4g, 5g, rate:MBPS, trace:PATH[@MBPS])");
    }
    return {};
}

// The faults: each value a list of numbers.
Status parseFault(std::string_view key, std::string_view value, LinkSpec& c, bool& known) {
    known = true;
    if (key == "ge") {
        double prl[3] = {0, 0, 1.0};
        if (!parseList(value, 2, 3, prl) || prl[0] < 0 || prl[0] >= 1 || prl[1] <= 0 ||
            prl[1] > 1 || prl[2] <= 0 || prl[2] > 1)
            return makeError(
                "must be P:R[:LOSS_BAD], P = P(good→bad) in [0, 1), R = P(bad→good) in "
                "(0, 1], LOSS_BAD = loss in the bad state in (0, 1] (default 1)");
        c.ge_p = prl[0];
        c.ge_r = prl[1];
        c.ge_loss_bad = prl[2];
    } else if (key == "reorder") {
        double pm[2] = {0, 5.0};
        if (!parseList(value, 1, 2, pm) || pm[0] < 0 || pm[0] >= 1 || pm[1] <= 0 || pm[1] > 10'000)
            return makeError("must be P[:MS], P in [0, 1), MS in (0, 10000]");
        c.reorder = pm[0];
        c.reorder_ms = pm[1];
    } else if (key == "spike") {
        double e[3] = {0, 0, 0};
        if (!parseList(value, 3, 3, e) || e[0] <= 0 || e[0] > 3'600'000 || e[1] <= 0 ||
            e[1] > e[0] || e[2] <= 0 || e[2] > 10'000)
            return makeError(
                "must be EVERY:LEN:EXTRA ms, 0 < LEN <= EVERY <= 3600000, 0 < EXTRA <= 10000");
        c.spike_every_ms = e[0];
        c.spike_len_ms = e[1];
        c.spike_extra_ms = e[2];
    } else {
        known = false;
    }
    return {};
}

// One option; the error says what the value must be (the caller names the spec and key).
Status parseOption(std::string_view key, std::string_view value, LinkSpec& c, bool& known) {
    known = true;
    double v = 0;
    uint64_t u = 0;
    if (key == "delay_ms" || key == "jitter_ms") {
        if (!parseDouble(value, v) || v < 0 || v > 10'000)
            return makeError("must be in [0, 10000] ms");
        (key == "delay_ms" ? c.delay_ms : c.jitter_ms) = v;
    } else if (key == "loss" || key == "dup") {
        if (!parseDouble(value, v) || v < 0 || v >= 1)
            return makeError("must be a probability in [0, 1)");
        (key == "loss" ? c.loss : c.duplicate) = v;
    } else if (key == "queue_kb") {
        if (!parseU64(value, u) || u == 0 || u > (1u << 20))
            return makeError("must be in [1, 1048576] KiB");
        c.queue_bytes = static_cast<int64_t>(u) * 1024;
    } else if (key == "seed") {
        if (!parseU64(value, u))
            return makeError("must be an unsigned integer");
        c.seed = u;
    } else {
        return parseFault(key, value, c, known);
    }
    return {};
}

}  // namespace

const std::vector<std::string>& linkProfileNames() {
    static const std::vector<std::string> names{"none", "wifi", "lte", "5g"};
    return names;
}

Expected<LinkSpec> parseLinkSpec(const std::string& spec) {
    std::vector<std::string_view> parts;
    std::string_view rest = spec;
    while (true) {
        const size_t comma = rest.find(',');
        parts.push_back(rest.substr(0, comma));
        if (comma == std::string_view::npos)
            break;
        rest.remove_prefix(comma + 1);
    }
    LinkSpec c;
    if (Status s = parseProfile(spec, parts[0], c); !s)
        return makeError(s.error());
    for (size_t i = 1; i < parts.size(); ++i) {
        const size_t eq = parts[i].find('=');
        if (eq == std::string_view::npos)
            return makeError("link '" + spec + "': option '" + std::string(parts[i]) +
                             "' is not key=value");
        const std::string_view key = parts[i].substr(0, eq);
        bool known = false;
        Status s = parseOption(key, parts[i].substr(eq + 1), c, known);
        if (!known)
            return makeError("link '" + spec + "': unknown option '" + std::string(key) +
                             "' (delay_ms, jitter_ms, loss, queue_kb, seed, ge, reorder, dup, "
                             "spike)");
        if (!s)
            return makeError("link '" + spec + "': " + std::string(key) + " " + s.error());
        ++c.options;
    }
    return c;
}

Expected<LinkSpec> loadLinkSpec(const std::string& spec) {
    auto c = parseLinkSpec(spec);
    if (!c || c->trace_path.empty())
        return c;
    auto trace = loadMahimahiTrace(c->trace_path);
    if (!trace)
        return makeError(trace.error());
    c->trace = std::make_shared<const MahimahiTrace>(std::move(trace).value());
    return c;
}

}  // namespace qvr
