// The designs of §6.1 as data: the simulator branches on traits, not on names.
#include "qvr/sim/design.h"

#include <array>

#include <fmt/format.h>

namespace qvr {

namespace {

const std::array<DesignTraits, 7> kTraits = {{
    {Design::Local, "local", Split::LocalOnly, "", false, false,
     "baseline: whole frame on the mobile GPU, ATW on the GPU"},
    {Design::Remote, "remote", Split::RemoteOnly, "", false, false,
     "server renders and streams the full frame; ATW on the GPU"},
    {Design::Static, "static", Split::Static, "", false, false,
     "foreground local, background + depth of frame n+1 prefetched; GPU composes by depth"},
    {Design::Ffr, "ffr", Split::Foveated, "fixed", false, false,
     "collaborative foveated, e1 = 5 deg; composition + ATW on the GPU"},
    {Design::Dfr, "dfr", Split::Foveated, "liwc", false, false,
     "collaborative foveated, LIWC picks e1; composition + ATW on the GPU"},
    {Design::Sw, "sw", Split::Foveated, "sw", false, true,
     "software Q-VR: e1 from measured latencies two frames late; no UCA"},
    {Design::Qvr, "qvr", Split::Foveated, "liwc", true, false,
     "Q-VR: LIWC + unified composition/ATW on two UCA units"},
}};

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

std::string designNamesList() {
    std::string s;
    for (const auto& t : kTraits) {
        if (!s.empty())
            s += ", ";
        s += t.name;
    }
    return s;
}

Expected<Design> designByName(const std::string& name) {
    for (const auto& t : kTraits)
        if (t.name == name)
            return t.design;
    return makeError(
        fmt::format("unknown design '{}': expected one of {}", name, designNamesList()));
}

}  // namespace qvr
