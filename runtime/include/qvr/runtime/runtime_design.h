// The designs the runtime runs for real (paper §6.1): what the headset renders, what it asks
// the server for, and which policy sizes the fovea.
#pragma once

#include <string>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr::runtime {

enum class RuntimeDesign {
    kLocal,   // everything on the headset
    kRemote,  // whole frames rendered by the server and streamed; the headset decodes + warps
    kFfr,     // fixed fovea e1 = 5°, periphery from the server
    kSw,      // software-reactive policy (measurements two frames late)
    kQvr,     // LIWC + UCA
    kFixed,   // a fixed fovea of any e1 ("fixed:E"); ffr is fixed:5 under its own name
};

// A design as the command line names it: the kind, and e1 for a fixed fovea.
struct DesignSpec {
    RuntimeDesign design = RuntimeDesign::kQvr;
    double fixed_e1_deg = 5.0;  // kFfr and kFixed
    std::string label() const;  // "qvr", "ffr", "fixed:10"
};

// The fixed fovea of the paper's FFR design.
inline constexpr double kFfrE1Deg = 5.0;
// e1 of a "fixed:E" design must lie in this range (degrees).
inline constexpr double kFixedE1MinDeg = 1.0;
inline constexpr double kFixedE1MaxDeg = 90.0;

const char* designName(RuntimeDesign design);
std::string designLabel(RuntimeDesign design, double fixed_e1_deg);
Expected<RuntimeDesign> runtimeDesignByName(const std::string& name);
// "local", …, "qvr" or "fixed:E" (E in degrees, kFixedE1MinDeg…kFixedE1MaxDeg).
Expected<DesignSpec> designSpecByName(const std::string& name);
const std::vector<RuntimeDesign>& allRuntimeDesigns();
// Comma-separated list of names ("local,remote,ffr,sw,qvr,fixed:10") → designs; errors name the
// bad one.
Expected<std::vector<DesignSpec>> parseDesignList(const std::string& list);
bool usesServer(RuntimeDesign design);

}  // namespace qvr::runtime
