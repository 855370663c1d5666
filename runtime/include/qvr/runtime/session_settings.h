// The render server's and the headset's settings as the command line spells them (`qvr server`,
// `qvr client`), and the configurations they make: the key read, the profile and link named,
// the renderer's level of detail set.
#pragma once

#include <cstdint>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/render_server.h"

namespace qvr::runtime {

struct ServerSettings {
    std::string bind = "127.0.0.1";
    uint16_t port = 7400;
    std::string key, key_file;  // exactly one (keyFromOptions)
    std::string profile = "default";
    std::string net = "none";  // a link spec (core/link_spec.h)
    std::string codec = "x264";
    int core = -1;
    int workers = 0;             // render workers (0: one per allowed core; 1 with `core`)
    double min_fps = 0.0;        // admission's frame-rate floor (0: off)
    double frame_cost_ms = 0.0;  // a calibrated server frame's cost (0: measure it)
    bool one_pass_periphery = false;
    bool no_holes = false;
    float lod_px = 1.0f;
    bool keep_frame_records = false;      // for a frames CSV
    std::string share_periphery = "off";  // off, auto or on (SharePeripheryMode)
};
// An error when the key, the profile or the link cannot be had.
Expected<RenderServerConfig> renderServerConfig(const ServerSettings& s);

struct HeadsetSettings {
    std::string host;
    uint16_t port = 7400;
    std::string key, key_file;  // exactly one (keyFromOptions)
    std::string profile = "default";
    std::string design = "qvr";  // parseDesign's runtime names
    std::string codec = "x264";
    int frames = 300;
    int core = -1;
    float lod_px = 1.0f;
};
// An error when the key, the design or the profile cannot be had.
Expected<HeadsetConfig> headsetConfig(const HeadsetSettings& s);

}  // namespace qvr::runtime
