// The inputs `qvr run`, `qvr client` and the tests share: the runtime's display profile, the
// head-motion and gaze traces placed in the scene, and the pre-shared key from the command line.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/net/auth.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/scene/scene.h"
#include "qvr/scene/triangle_bvh.h"

namespace qvr::runtime {

// "run": the default HMD's 100°×110° field at 480×540 per eye, a quarter of 1920×2160 on each
// axis, for quick runs (`qvr run` defaults to "default", the paper's display, docs/RUNTIME.md).
// "small": 320×360 for tests. Anything else goes to hmdProfileByName ("default", "low", a TOML
// path).
Expected<HmdProfile> runtimeProfileByName(const std::string& name);

// motion: "default" (the CMU BVH that `qvr trace motion --default` uses), a .bvh path, a pose
// CSV, or "still" (the spawn pose, no motion). gaze: "model" (seeded fixations and saccades),
// "center", or a gaze CSV. BVH motion is placed at the scene's first spawn point.
Expected<HeadsetTraces> makeTraces(const std::string& motion, const std::string& gaze,
                                   const Scene& scene, double refresh_hz, int frames,
                                   uint64_t seed);

// The traces played `ms` ahead: at time t they give what they gave at t + ms (the last sample
// held past its end). Headsets on one path a fraction of a frame apart never repeat each other's
// poses (qvr run --headset-offset-ms).
void playAhead(HeadsetTraces& traces, double ms);

// What a headset runs on: the scene (with its BVH for LIWC's ring counts) and the traces placed
// in it, loaded from the command line's spellings (makeTraces for motion and gaze).
struct HeadsetInputs {
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<const TriangleBvh> bvh;
    HeadsetTraces traces;
};
Expected<HeadsetInputs> loadHeadsetInputs(const std::string& scene, const std::string& motion,
                                          const std::string& gaze, double refresh_hz, int frames,
                                          uint64_t seed);

// --key: 64 hex digits, or "pass:TEXT" for a passphrase (hashed; loopback only). --key-file: a
// file holding either form on its first line. Exactly one must be non-empty.
Expected<net::PresharedKey> keyFromOptions(const std::string& key, const std::string& key_file);

}  // namespace qvr::runtime
