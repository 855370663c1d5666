// The system designs (paper §6.1, Fig. 12) as both the simulator and the runtime name them:
// what each renders where, who picks the fovea, and which unit composes and timewarps. One
// vocabulary for both sides, in core because it is plain data both depend on: the policies
// (controller) and the pipelines (sim, runtime) branch on these traits, not on names.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr {

// The paper's seven designs, then Fixed: a fixed fovea of any e1 ("fixed:E"; ffr is fixed:5
// under its own name), and Aimd: a network-driven baseline that sizes the fovea from the link's
// queuing delay alone (EyeNexus's controller, docs/LIWC.md).
enum class Design { Local, Remote, Static, Ffr, Dfr, Sw, Qvr, Fixed, Aimd };

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
    std::string_view policy;        // "" (no fovea), "fixed", "liwc", "sw" or "aimd"
    bool uca = false;               // composition + ATW on the UCA units instead of the GPU
    bool software_control = false;  // e1 picked by the CPU from read-back timers
    bool runtime = false;           // the runtime runs it (static and dfr are simulated only)
    std::string_view summary;
};

// The fixed fovea of the paper's FFR design.
inline constexpr double kFfrE1Deg = 5.0;
// e1 of a "fixed:E" design must lie in this range (degrees).
inline constexpr double kFixedE1MinDeg = 1.0;
inline constexpr double kFixedE1MaxDeg = 90.0;

const DesignTraits& traitsOf(Design d);
// The paper's seven, in Fig. 12's order: what the simulator compares.
const std::vector<Design>& allDesigns();
// The named designs the runtime runs: local, remote, ffr, sw, qvr, aimd (and fixed:E, by its e1).
const std::vector<Design>& runtimeDesigns();
// Whether the server renders anything for the design.
bool usesServer(Design design);

// A design as a command line names it: the design, and e1 for a fixed fovea.
struct DesignSpec {
    Design design = Design::Qvr;
    double fixed_e1_deg = kFfrE1Deg;  // Ffr and Fixed
    std::string label() const;        // "qvr", "ffr", "fixed:10"
};
std::string designLabel(Design design, double fixed_e1_deg);

// Who reads the name: the simulator takes the paper's seven and aimd; the runtime (and the
// simulator's model of it) takes local, remote, ffr, sw, qvr, aimd and fixed:E, and refuses static
// and dfr with a message that says they are simulated only.
enum class DesignScope { Simulator, Runtime };

// "local", "remote", "static", "ffr", "dfr", "sw", "qvr", "aimd" or "fixed:E" (E in degrees,
// kFixedE1MinDeg…kFixedE1MaxDeg), as `scope` allows; errors name the input.
Expected<DesignSpec> parseDesign(const std::string& name, DesignScope scope);
// Comma-separated names ("local,remote,ffr,sw,qvr,fixed:10"); empty items are skipped, a design
// named twice (by label) is an error.
Expected<std::vector<DesignSpec>> parseDesignList(const std::string& list, DesignScope scope);
// The simulator's parse, for a single design: parseDesign(name, DesignScope::Simulator).
Expected<Design> designByName(const std::string& name);
std::string designNamesList();  // "local, remote, …" (the paper's seven) for messages

}  // namespace qvr
