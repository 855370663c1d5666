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
};

const char* designName(RuntimeDesign design);
Expected<RuntimeDesign> runtimeDesignByName(const std::string& name);
const std::vector<RuntimeDesign>& allRuntimeDesigns();
// Comma-separated list of names ("local,remote,ffr,sw,qvr") → designs; errors name the bad one.
Expected<std::vector<RuntimeDesign>> parseDesignList(const std::string& list);
bool usesServer(RuntimeDesign design);

}  // namespace qvr::runtime
