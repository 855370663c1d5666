// Shared periphery (docs/RUNTIME.md §Shared periphery): headsets of one scene whose head poses are
// close get one outer layer per eye rendered for all of them — at the finest of their outer
// sampling rates, over the union of their outer rectangles — each reduced to its own layer rect;
// those for whom one render of the union of their middle layers costs fewer texels than theirs
// share the middle layer the same way. Sharing a layer is kept
// for a headset only while the SSIM of the shared layer against its own stays above a threshold
// in every eccentricity band.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "qvr/core/expected.h"
#include "qvr/core/image.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/renderer.h"

namespace qvr::runtime {

enum class SharePeripheryMode {
    kOff,   // every headset its own outer layer
    kAuto,  // shared among close headsets while the measured SSIM holds
    kOn,    // shared among close headsets without measuring (for cost measurements)
};
Expected<SharePeripheryMode> parseSharePeripheryMode(const std::string& name);
const char* sharePeripheryModeName(SharePeripheryMode mode);

struct SharePeripheryConfig {
    SharePeripheryMode mode = SharePeripheryMode::kOff;
    // Poses this close are candidates: the member's UCA takes a shared layer as rendered at its
    // own pose, so the difference shows as misregistration (the SSIM measures what it costs).
    // Also the group layer's margin: what a member this far off brings into view.
    double max_angle_deg = 3.0;
    double max_position_m = 0.10;
    // Every eccentricity band's SSIM (luma, 7×7 windows) of the shared layer against the
    // headset's own must be at least this (docs/RUNTIME.md says why 0.9).
    double min_ssim = 0.90;
    double band_deg = 10.0;
    // A headset's verdict is measured again after this many of its frames.
    int remeasure_frames = 90;
};

bool posesClose(const Pose& a, const Pose& b, const SharePeripheryConfig& c);
// Poses this close see the same texels: 0.01° is a fifth of the finest layer's texel (a
// full-resolution pixel of the default profile spans ~0.05°); 0.1 mm moves a point 0.6 m away
// by 0.01°.
constexpr double kSamePoseDeg = 0.01;
constexpr double kSamePoseM = 1e-4;
bool samePose(const Pose& a, const Pose& b);
// The middle layer is centred on the gaze: two headsets share it while one render of the union
// of their middle layers (at the finer scale, each eye) costs fewer texels than their two.
bool middleUnionPays(const LayerPlan& a, const LayerPlan& b);
// The layers a server may share: the middle and the outer one.
bool isShareable(LayerKind kind);

// Groups by pose: each pose joins the first group whose first member (its leader) is close,
// else starts a group. Indices into `poses`, groups in order of their leaders.
std::vector<std::vector<size_t>> groupByPose(const std::vector<Pose>& poses,
                                             const SharePeripheryConfig& c);

// One eccentricity band [lo_deg, hi_deg) of a middle or outer layer.
struct BandSsim {
    double lo_deg = 0.0;
    double hi_deg = 0.0;
    double ssim = 0.0;
    int64_t texels = 0;
};

// SSIM of `shared` (the shared layer as the headset gets it: reduced to its own layer `kind`)
// against `own` (its own layer) by eccentricity band of band_deg from the plan's gaze. Texels
// nearer the gaze than hide_below_deg (what the compositor takes from a finer layer only) are
// left out; bands without a whole 7×7 window are left out.
std::vector<BandSsim> layerSsimByBand(const HmdProfile& profile, const LayerPlan& plan, Eye eye,
                                      LayerKind kind, const ImageRgba8& shared,
                                      const ImageRgba8& own, double band_deg,
                                      double hide_below_deg);
bool bandsPass(const std::vector<BandSsim>& bands, double min_ssim);

// The bounds, in an eye image seen from orientation `render`, of `rect` in the eye image seen from
// `member` (a flat pinhole rotation of its edges): what a render at `render` must cover for the
// member to take it. `rect` itself when the two are the same.
PixelRect rotatedRect(const HmdProfile& profile, const PixelRect& rect, const glm::quat& render,
                      const glm::quat& member);

// Where the group's members are expected to look from when they take its render: of[i] holds
// member i's orientations (none: the render's own), `render` the render's orientation.
struct MemberViews {
    glm::quat render{1.0f, 0.0f, 0.0f, 0.0f};
    std::vector<std::vector<glm::quat>> of;
};

// The layer `kind` the group renders for one eye: the union of its members' rectangles, each
// as seen from the render's orientation when the member looks from each of its views
// (rotatedRect), widened to what a rotation of margin_deg either way brings into view, at the
// finest of their sampling scales, with the plan (gaze, e1 or e2) whose hole every member can
// take (holes off when the members' gazes differ).
struct SharedLayer {
    LayerPlan plan;  // a member's plan with layerOf(eyes[eye], kind) the shared rect
    LayerHoles holes;
};
SharedLayer sharedLayerPlan(const HmdProfile& profile, const std::vector<LayerPlan>& members,
                            Eye eye, LayerKind kind, const LayerHoles& holes,
                            double margin_deg = 0.0, const MemberViews& views = {});

// A shared layer as one member gets it: its layer's texels, rotated from the shared render's
// orientation to the member's (bilinear), or box-filtered when the two are the same. The
// member's UCA then takes it as rendered at its own pose; position is not corrected.
void reduceSharedLayer(const ImageRgba8& shared, const LayerRect& shared_rect,
                       const LayerRect& member_rect, ImageRgba8& out, const HmdProfile& profile,
                       const glm::quat& shared_orientation, const glm::quat& member_orientation);

struct SharePeripheryStats {
    std::string mode = "off";
    double min_ssim = 0.0;
    double band_deg = 0.0;
    // Per shareable layer (middle, outer), each eye's layers counted.
    struct Layers {
        uint64_t own = 0;     // rendered for one headset
        uint64_t shared = 0;  // rendered for a group (and reduced for the renderer)
        uint64_t reused = 0;  // taken from another headset's shared render
    };
    Layers middle, outer;
    Layers& of(LayerKind kind) { return kind == LayerKind::kMiddle ? middle : outer; }
    uint64_t measurements = 0;
    uint64_t measurements_failed = 0;  // some band below min_ssim
    // Over the group renders: their margin_deg, their texels and their renderer's own layer's.
    double margin_deg_sum = 0.0;
    uint64_t group_texels = 0, own_texels = 0;
    // By layer and band over every measurement: the mean and the lowest SSIM.
    struct Band {
        std::string layer;  // "middle" or "outer"
        double lo_deg = 0.0, hi_deg = 0.0;
        double ssim_mean = 0.0, ssim_min = 1.0;
        uint64_t measurements = 0;
    };
    std::vector<Band> ssim_by_band;
};
nlohmann::json sharePeripheryJson(const SharePeripheryStats& s, double service_ms_per_frame);

// The server's sharing state, thread-safe: the sessions' latest poses and plans, the newest
// shared layers each session rendered per layer and eye, each session's SSIM verdicts.
class SharedPeriphery {
public:
    using Id = uint64_t;
    explicit SharedPeriphery(SharePeripheryConfig config);

    const SharePeripheryConfig& config() const { return m_config; }
    void join(Id id);                                                  // a session connected
    void noteRequest(Id id, const Pose& pose, const LayerPlan& plan);  // a joined session's frame
    void forget(Id id);

    enum class Action {
        kOwn,           // render its own layer
        kRenderShared,  // render `shared` for the group, then store() it
        kReuse,         // `image` holds the layer, reduced from another's shared render
        kMeasure,       // `image` holds a candidate; render its own, measured(), send its own
    };
    struct Decision {
        Action action = Action::kOwn;
        SharedLayer shared;
        ImageRgba8 image;
        // kOwn: another headset may take this render later (it follows this one's path a few
        // frames behind), so store() it with the headset's own plan once rendered.
        bool keep = false;
    };
    // For a shareable layer `kind` of this headset's frame (holes: the server's).
    Decision decide(Id id, Eye eye, LayerKind kind, const Pose& pose, const LayerPlan& plan,
                    const HmdProfile& profile, const LayerHoles& holes);
    void store(Id renderer, Eye eye, LayerKind kind, const Pose& pose, const SharedLayer& shared,
               ImageRgba8 image);
    void measured(Id id, Eye eye, LayerKind kind, const std::vector<BandSsim>& bands);
    void countOwn(LayerKind kind);
    SharePeripheryStats stats() const;

private:
    struct Entry {
        Pose pose;
        SharedLayer shared;  // the plan it was rendered with
        std::shared_ptr<const ImageRgba8> image;
        std::set<Id> consumed;  // the members it was given to
        uint64_t serial = 0;    // newer renders have larger serials
    };
    struct Session {
        Pose pose;
        LayerPlan plan;
        bool posed = false;  // a request noted
        // The orientation of the request before `pose`'s, and how far each of the last
        // kMissesKept requests landed from the orientation extrapolated from the two before it.
        std::optional<glm::quat> previous;
        std::deque<double> misses_deg;
        // Per slot (layer and eye, slotOf): its newest kRendersKept shared renders, whether the
        // last measurement passed, and the frames since.
        std::array<std::deque<Entry>, 4> entries;
        std::array<std::optional<bool>, 4> verdict;
        std::array<int, 4> frames_since_measure{};
        // Per slot: its last decision took a render made at its own pose (samePose): it
        // follows another's path a few frames behind and will find that one's renders of the
        // poses it comes to, so a group render need not reach where it looks from now.
        std::array<bool, 4> follows{};
    };
    static size_t slotOf(LayerKind kind, Eye eye);
    // Renders kept per session and slot, group renders and kept own ones: a headset up to
    // kRendersKept - 1 frames behind another on its path takes the one of its own pose (two
    // headsets started together run 2-8 frames apart) (bounded: at most 16 × 4 layers per
    // session in memory, 32 MB of the default profile's).
    static constexpr size_t kRendersKept = 16;
    // Requests over which a session's extrapolation miss is taken (its largest): about a second.
    static constexpr size_t kMissesKept = 16;
    // Where a member is expected to look from when it takes a render: its newest request's
    // orientation and the next one extrapolated from the two newest; and the largest miss of that
    // extrapolation over its last requests (max_angle_deg until there is one).
    static std::vector<glm::quat> expectedViews(const Session& s);
    double expectedMissDeg(const Session& s) const;
    // The members `id` shares layer `kind` with: its pose group, for the middle layer only those
    // with whom one render of the union pays (middleUnionPays).
    std::vector<Id> groupOfLocked(Id id, LayerKind kind) const;
    bool dueLocked(const Session& s, size_t slot) const;  // a measurement is due
    // Another member of the group would take a group render: its gate passed or is due.
    bool anyTakerLocked(const std::vector<Id>& group, Id id, size_t slot) const;
    // Another member's render this headset can take: close pose, covering its layer at least as
    // finely, a hole no larger than its own, not given to it yet unless made at its very pose.
    bool usableLocked(const Entry& entry, Id id, Eye eye, LayerKind kind, const Pose& pose,
                      const LayerPlan& plan, const HmdProfile& profile,
                      const LayerHoles& holes) const;

    SharePeripheryConfig m_config;
    mutable std::mutex m_mutex;
    std::map<Id, Session> m_sessions;
    SharePeripheryStats m_stats;
    uint64_t m_serial = 0;
};

}  // namespace qvr::runtime
