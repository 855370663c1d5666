// The seven system designs the paper compares (§6.1, Fig. 12): what each renders where, who
// picks the fovea, and which unit composes and timewarps.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr {

enum class Design { Local, Remote, Static, Ffr, Dfr, Sw, Qvr };

enum class Split {
    LocalOnly,   // every triangle and pixel on the headset
    RemoteOnly,  // the server renders the full frame and streams it
    Static,      // foreground objects local, background + depth of frame n+1 prefetched
    Foveated,    // fovea local at full resolution, middle + outer layers streamed (§3)
};

struct DesignTraits {
    Design design = Design::Local;
    std::string_view name;
    Split split = Split::LocalOnly;
    std::string_view policy;        // "" (no fovea), "fixed", "liwc" or "sw"
    bool uca = false;               // composition + ATW on the UCA units instead of the GPU
    bool software_control = false;  // e1 picked by the CPU from read-back timers
    std::string_view summary;
};

const DesignTraits& traitsOf(Design d);
const std::vector<Design>& allDesigns();
Expected<Design> designByName(const std::string& name);
std::string designNamesList();  // "local, remote, …" for messages

}  // namespace qvr
