// The designs of §6.1 as data: the pipelines branch on traits, not on names.
#include "qvr/core/design.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

namespace qvr {

namespace {

const std::array<DesignTraits, 9> kTraits = {{
    {Design::Local, "local", Split::LocalOnly, "", false, false, true,
     "baseline: whole frame on the mobile GPU, ATW on the GPU"},
    {Design::Remote, "remote", Split::RemoteOnly, "", false, false, true,
     "server renders and streams the full frame; ATW on the GPU"},
    {Design::Static, "static", Split::Static, "", false, false, false,
     "foreground local, background + depth of frame n+1 prefetched; GPU composes by depth"},
    {Design::Ffr, "ffr", Split::Foveated, "fixed", false, false, true,
     "collaborative foveated, e1 = 5 deg; composition + ATW on the GPU"},
    {Design::Dfr, "dfr", Split::Foveated, "liwc", false, false, false,
     "collaborative foveated, LIWC picks e1; composition + ATW on the GPU"},
    {Design::Sw, "sw", Split::Foveated, "sw", false, true, true,
     "software Q-VR: e1 from measured latencies two frames late; no UCA"},
    {Design::Qvr, "qvr", Split::Foveated, "liwc", true, false, true,
     "Q-VR: LIWC + unified composition/ATW on two UCA units"},
    {Design::Fixed, "fixed", Split::Foveated, "fixed", false, false, true,
     "collaborative foveated with a fixed fovea of any e1 (fixed:E)"},
    {Design::Aimd, "aimd", Split::Foveated, "aimd", false, false, true,
     "baseline: e1 from the link's queuing delay by AIMD (EyeNexus), blind to rendering costs"},
}};

// The designs a name may select: the paper's seven, then the baselines beyond the paper.
const std::vector<Design>& namedDesigns() {
    static const std::vector<Design> named = {Design::Local, Design::Remote, Design::Static,
                                              Design::Ffr,   Design::Dfr,    Design::Sw,
                                              Design::Qvr,   Design::Aimd};
    return named;
}

constexpr std::string_view kFixedPrefix = "fixed:";
constexpr const char* kRuntimeNames = "local, remote, ffr, sw, qvr, aimd or fixed:E";

Expected<DesignSpec> parseFixed(const std::string& name) {
    const std::string_view num = std::string_view(name).substr(kFixedPrefix.size());
    double e1 = 0.0;
    const auto [end, ec] = std::from_chars(num.data(), num.data() + num.size(), e1);
    if (num.empty() || ec != std::errc() || end != num.data() + num.size() || !std::isfinite(e1) ||
        e1 < kFixedE1MinDeg || e1 > kFixedE1MaxDeg)
        return makeError(fmt::format("design '{}': fixed:E needs E in degrees, {:g}…{:g}", name,
                                     kFixedE1MinDeg, kFixedE1MaxDeg));
    return DesignSpec{Design::Fixed, e1};
}

}  // namespace

const DesignTraits& traitsOf(Design d) {
    return kTraits[static_cast<size_t>(d)];
}

const std::vector<Design>& allDesigns() {
    static const std::vector<Design> all = {Design::Local, Design::Remote, Design::Static,
                                            Design::Ffr,   Design::Dfr,    Design::Sw,
                                            Design::Qvr};
    return all;
}

const std::vector<Design>& runtimeDesigns() {
    static const std::vector<Design> designs = {Design::Local, Design::Remote, Design::Ffr,
                                                Design::Sw,    Design::Qvr,    Design::Aimd};
    return designs;
}

bool usesServer(Design design) {
    return traitsOf(design).split != Split::LocalOnly;
}

std::string designLabel(Design design, double fixed_e1_deg) {
    if (design == Design::Fixed)
        return fmt::format("fixed:{:g}", fixed_e1_deg);
    return std::string(traitsOf(design).name);
}

std::string DesignSpec::label() const {
    return designLabel(design, fixed_e1_deg);
}

std::string designNamesList() {
    std::string s;
    for (Design d : allDesigns()) {
        if (!s.empty())
            s += ", ";
        s += traitsOf(d).name;
    }
    return s;
}

Expected<DesignSpec> parseDesign(const std::string& name, DesignScope scope) {
    const bool runtime = scope == DesignScope::Runtime;
    if (name.starts_with(kFixedPrefix)) {
        if (!runtime)
            return makeError(
                fmt::format("unknown design '{}': expected one of {} (fixed:E is the runtime's)",
                            name, designNamesList()));
        return parseFixed(name);
    }
    if (runtime && name == "fixed")
        return makeError("design 'fixed' needs its e1: fixed:E, e.g. fixed:10");
    for (Design d : namedDesigns()) {
        const DesignTraits& t = traitsOf(d);
        if (t.name != name)
            continue;
        if (runtime && !t.runtime)
            return makeError(fmt::format("design '{}' is simulated only: the runtime runs {}", name,
                                         kRuntimeNames));
        return DesignSpec{d, kFfrE1Deg};
    }
    if (runtime)
        return makeError(fmt::format("unknown design '{}': expected {}", name, kRuntimeNames));
    return makeError(
        fmt::format("unknown design '{}': expected one of {}", name, designNamesList()));
}

Expected<std::vector<DesignSpec>> parseDesignList(const std::string& list, DesignScope scope) {
    std::vector<DesignSpec> out;
    size_t pos = 0;
    while (pos <= list.size()) {
        const size_t comma = std::min(list.find(',', pos), list.size());
        const std::string item = list.substr(pos, comma - pos);
        pos = comma + 1;
        if (item.empty())
            continue;
        auto d = parseDesign(item, scope);
        if (!d)
            return makeError(d.error());
        for (const DesignSpec& seen : out)
            if (seen.label() == d->label())
                return makeError(fmt::format("design '{}' named twice", item));
        out.push_back(*d);
    }
    if (out.empty())
        return makeError("no design named in '" + list + "'");
    return out;
}

Expected<Design> designByName(const std::string& name) {
    auto spec = parseDesign(name, DesignScope::Simulator);
    if (!spec)
        return makeError(spec.error());
    return spec->design;
}

}  // namespace qvr
