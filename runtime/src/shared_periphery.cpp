// Shared periphery: grouping by pose (the middle layer while its union pays), the group's layer,
// and the SSIM gate by eccentricity band (shared_periphery.h).
#include "qvr/runtime/shared_periphery.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "qvr/compose/bilinear_span.h"
#include "qvr/compose/quality.h"
#include "qvr/compose/warp.h"
#include "qvr/core/check.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/render/periphery_pass.h"

namespace qvr::runtime {

Expected<SharePeripheryMode> parseSharePeripheryMode(const std::string& name) {
    if (name == "off")
        return SharePeripheryMode::kOff;
    if (name == "auto")
        return SharePeripheryMode::kAuto;
    if (name == "on")
        return SharePeripheryMode::kOn;
    return makeError("share-periphery mode '" + name + "': expected off, auto or on");
}

const char* sharePeripheryModeName(SharePeripheryMode mode) {
    switch (mode) {
        case SharePeripheryMode::kAuto:
            return "auto";
        case SharePeripheryMode::kOn:
            return "on";
        case SharePeripheryMode::kOff:
            break;
    }
    return "off";
}

bool posesClose(const Pose& a, const Pose& b, const SharePeripheryConfig& c) {
    return angleBetweenDeg(a.orientation, b.orientation) <= c.max_angle_deg &&
           double(glm::length(a.position_m - b.position_m)) <= c.max_position_m;
}

bool samePose(const Pose& a, const Pose& b) {
    return angleBetweenDeg(a.orientation, b.orientation) <= kSamePoseDeg &&
           double(glm::length(a.position_m - b.position_m)) <= kSamePoseM;
}

bool isShareable(LayerKind kind) {
    return kind == LayerKind::kMiddle || kind == LayerKind::kOuter;
}

std::vector<std::vector<size_t>> groupByPose(const std::vector<Pose>& poses,
                                             const SharePeripheryConfig& c) {
    std::vector<std::vector<size_t>> groups;
    for (size_t i = 0; i < poses.size(); ++i) {
        auto g = std::find_if(groups.begin(), groups.end(), [&](const std::vector<size_t>& x) {
            return posesClose(poses[x.front()], poses[i], c);
        });
        if (g == groups.end())
            groups.push_back({i});
        else
            g->push_back(i);
    }
    return groups;
}

std::vector<BandSsim> layerSsimByBand(const HmdProfile& profile, const LayerPlan& plan, Eye eye,
                                      LayerKind kind, const ImageRgba8& shared,
                                      const ImageRgba8& own, double band_deg,
                                      double hide_below_deg) {
    QVR_CHECK(band_deg >= 1.0);
    QVR_CHECK(shared.width() == own.width() && shared.height() == own.height());
    const LayerRect& layer = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
    const EyeGeometry geometry(profile);
    const int bands = static_cast<int>(std::ceil(180.0 / band_deg));
    std::vector<uint8_t> labels(static_cast<size_t>(own.width()) * size_t(own.height()), 0);
    for (int j = 0; j < own.height(); ++j) {
        for (int i = 0; i < own.width(); ++i) {
            const double e_deg =
                geometry.eccentricityDeg(plan.gaze, layer.rect.x0 + (i + 0.5) * layer.scale,
                                         layer.rect.y0 + (j + 0.5) * layer.scale);
            if (e_deg < hide_below_deg)
                continue;
            labels[size_t(j) * size_t(own.width()) + size_t(i)] =
                static_cast<uint8_t>(std::min(bands, 1 + static_cast<int>(e_deg / band_deg)));
        }
    }
    const std::vector<RegionQuality> q = measureLabelledQuality(shared, own, labels, bands);
    std::vector<BandSsim> out;
    for (int b = 0; b < bands; ++b) {
        const RegionQuality& r = q[static_cast<size_t>(b)];
        if (r.ssim_windows > 0)
            out.push_back({b * band_deg, (b + 1) * band_deg, r.ssim, r.pixels});
    }
    return out;
}

bool bandsPass(const std::vector<BandSsim>& bands, double min_ssim) {
    return std::all_of(bands.begin(), bands.end(),
                       [&](const BandSsim& b) { return b.ssim >= min_ssim; });
}

namespace {

LayerRect& mutableLayerOf(EyeLayers& layers, LayerKind kind) {
    return kind == LayerKind::kMiddle ? layers.middle : layers.outer;
}

// The rotation between two orientations of the eye without the lens, which the layers do not have.
EyeWarp flatWarp(const HmdProfile& profile, const glm::quat& render, const glm::quat& member) {
    HmdProfile flat = profile;
    flat.lens = LensProfile{0.0, 0.0, 1.0, 1.0};
    return EyeWarp(flat, render, member);
}

PixelRect unite(const PixelRect& a, const PixelRect& b) {
    return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

}  // namespace

bool middleUnionPays(const LayerPlan& a, const LayerPlan& b) {
    for (size_t e = 0; e < a.eyes.size(); ++e) {
        const LayerRect& x = a.eyes[e].middle;
        const LayerRect& y = b.eyes[e].middle;
        if (x.empty() || y.empty())
            return false;
        const PixelRect u = unite(x.rect, y.rect);
        const double scale = std::min(x.scale, y.scale);
        if (double(u.area()) / (scale * scale) >= double(x.pixels() + y.pixels()))
            return false;
    }
    return true;
}

PixelRect rotatedRect(const HmdProfile& profile, const PixelRect& rect, const glm::quat& render,
                      const glm::quat& member) {
    if (rect.empty() || angleBetweenDeg(render, member) <= 1e-6)
        return rect;
    const EyeWarp warp = flatWarp(profile, render, member);
    // A rotation bends straight edges: their images are bounded by enough points along them.
    constexpr int kSteps = 16;
    double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
    auto take = [&](double x, double y) {
        const glm::dvec3 r = warp.rotation() * glm::dvec3((x - warp.cx()) / warp.fx(),
                                                          -(y - warp.cy()) / warp.fy(), -1.0);
        const double depth = std::max(-r.z, 1e-6);  // behind the eye: unbounded
        const double u = warp.cx() + warp.fx() * r.x / depth;
        const double v = warp.cy() - warp.fy() * r.y / depth;
        x0 = std::min(x0, u), x1 = std::max(x1, u), y0 = std::min(y0, v), y1 = std::max(y1, v);
    };
    for (int k = 0; k <= kSteps; ++k) {
        const double t = double(k) / kSteps;
        const double x = rect.x0 + t * rect.width(), y = rect.y0 + t * rect.height();
        take(x, rect.y0), take(x, rect.y1), take(rect.x0, y), take(rect.x1, y);
    }
    constexpr double kLimit = 1e7;  // pixels: far beyond any image
    auto px = [&](double v, bool up) {
        v = std::clamp(v, -kLimit, kLimit);
        return static_cast<int>(up ? std::ceil(v - 1e-6) : std::floor(v + 1e-6));
    };
    return {px(x0, false), px(y0, false), px(x1, true), px(y1, true)};
}

SharedLayer sharedLayerPlan(const HmdProfile& profile, const std::vector<LayerPlan>& members,
                            Eye eye, LayerKind kind, const LayerHoles& holes, double margin_deg,
                            const MemberViews& views) {
    QVR_CHECK(!members.empty() && isShareable(kind));
    const size_t e = static_cast<size_t>(eye);
    SharedLayer s{members.front(), holes};
    LayerRect& u = mutableLayerOf(s.plan.eyes[e], kind);
    u.rect = PixelRect{};
    double min_hole_deg = 1e9;
    for (size_t i = 0; i < members.size(); ++i) {
        const LayerPlan& m = members[i];
        const LayerRect& o = layerOf(m.eyes[e], kind);
        if (o.empty())
            continue;
        u.scale = u.rect.empty() ? o.scale : std::min(u.scale, o.scale);
        const bool viewed = i < views.of.size() && !views.of[i].empty();
        if (!viewed)
            u.rect = u.rect.empty() ? o.rect : unite(u.rect, o.rect);
        for (size_t k = 0; viewed && k < views.of[i].size(); ++k) {
            const PixelRect seen = rotatedRect(profile, o.rect, views.render, views.of[i][k]);
            u.rect = u.rect.empty() ? seen : unite(u.rect, seen);
        }
        min_hole_deg = std::min(min_hole_deg, layerHoleDeg(profile, m, eye, kind, holes));
        const bool same_gaze = std::fabs(m.gaze.x_deg - s.plan.gaze.x_deg) < 1e-6 &&
                               std::fabs(m.gaze.y_deg - s.plan.gaze.y_deg) < 1e-6;
        if (!same_gaze)
            s.holes.enabled = false;  // their holes are different discs
    }
    // What a member rotated by up to margin_deg either way sees, so its reprojection stays inside
    // (eight directions; one rotated further is refused by usableLocked's exact check).
    if (margin_deg > 0.0 && !u.empty()) {
        const PixelRect r = u.rect;
        const glm::quat identity(1.0f, 0.0f, 0.0f, 0.0f);
        for (int k = 0; k < 8; ++k) {
            const double a = k * std::numbers::pi / 4.0;
            const glm::quat q =
                quatFromEulerDeg({margin_deg * std::cos(a), margin_deg * std::sin(a), 0.0});
            u.rect = unite(u.rect, rotatedRect(profile, r, identity, q));
        }
    }
    u.width_px = static_cast<int>(std::ceil(u.rect.width() / u.scale - 1e-9));
    u.height_px = static_cast<int>(std::ceil(u.rect.height() / u.scale - 1e-9));
    (kind == LayerKind::kMiddle ? s.plan.s1 : s.plan.s2) = u.scale;
    if (!(min_hole_deg > 0.0 && min_hole_deg < 1e9))
        s.holes.enabled = false;
    if (s.holes.enabled)  // the hole every member can take: the smallest of theirs
        (kind == LayerKind::kMiddle ? s.plan.e1_deg : s.plan.e2_deg) =
            min_hole_deg +
            (holes.band_texels + holes.margin_texels) * u.scale * profile.pixelAngleDeg();
    return s;
}

namespace {

// The member's texel centres through the rotation to the shared render (UCA's map without the
// lens, which the layers do not have). A flat pinhole rotation is a homography: its exact image is
// taken every kSpan texels along a row and stepped linearly between (a turn of 3° in yaw and
// pitch bends it off its chord by at most 0.06 texel over a span, at the corners of a ±50° view),
// each texel a fixed-point bilinear tap (bilinearSpans: a vector of taps at a time).
void warpSharedLayer(const ImageRgba8& shared, const LayerRect& shared_rect,
                     const LayerRect& member, ImageRgba8& out, const HmdProfile& profile,
                     const glm::quat& shared_orientation, const glm::quat& member_orientation) {
    const EyeWarp warp = flatWarp(profile, shared_orientation, member_orientation);
    const glm::dmat3& rot = warp.rotation();
    out.resize(member.width_px, member.height_px);
    // A member texel (i, j) is the eye-space ray d = (xt, yt, -1), affine in (i, j).
    const double s = member.scale;
    const glm::dvec3 d0((member.rect.x0 + 0.5 * s - warp.cx()) / warp.fx(),
                        -(member.rect.y0 + 0.5 * s - warp.cy()) / warp.fy(), -1.0);
    const glm::dvec3 r0 = rot * d0;
    const glm::dvec3 di = rot * glm::dvec3(s / warp.fx(), 0.0, 0.0);
    const glm::dvec3 dj = rot * glm::dvec3(0.0, -s / warp.fy(), 0.0);
    // Shared texel coordinates (centres at k + 0.5) of a rendered-eye point.
    const double ax = warp.fx() / shared_rect.scale,
                 bx = (warp.cx() - shared_rect.rect.x0) / shared_rect.scale - 0.5;
    const double ay = warp.fy() / shared_rect.scale,
                 by = (warp.cy() - shared_rect.rect.y0) / shared_rect.scale - 0.5;
    auto texel = [&](const glm::dvec3& r) {
        const double depth = std::max(-r.z, 1e-9);
        return glm::dvec2(bx + ax * r.x / depth, by - ay * r.y / depth);
    };
    constexpr int kSpan = 16;
    constexpr double kOne = 65536.0;  // 16.16 fixed point
    std::vector<FixedSpan> spans(static_cast<size_t>((member.width_px + kSpan - 1) / kSpan));
    for (int j = 0; j < member.height_px; ++j) {
        const glm::dvec3 row = r0 + double(j) * dj;
        glm::dvec2 a = texel(row);
        for (size_t k = 0; k < spans.size(); ++k) {
            const int i0 = int(k) * kSpan;
            const int n = std::min(kSpan, member.width_px - i0);
            const glm::dvec2 b = texel(row + double(i0 + n) * di);
            spans[k] = {std::llround(a.x * kOne), std::llround(a.y * kOne),
                        std::llround((b.x - a.x) / n * kOne), std::llround((b.y - a.y) / n * kOne),
                        n};
            a = b;
        }
        bilinearSpans(shared, spans.data(), spans.size(),
                      out.data() + static_cast<size_t>(j) * member.width_px * 4);
    }
}

bool sameScale(const LayerRect& a, const LayerRect& b) {
    return std::fabs(a.scale - b.scale) <= 1e-9;
}

// The member's layer cut out of the shared render: the same orientation and scale, and its
// texels on the render's grid (a box filter of one texel is a copy: cropMiddle's).
bool cropSharedLayer(const ImageRgba8& shared, const LayerRect& shared_rect,
                     const LayerRect& member, ImageRgba8& out) {
    if (!sameScale(shared_rect, member))
        return false;
    const double ox = (member.rect.x0 - shared_rect.rect.x0) / shared_rect.scale;
    const double oy = (member.rect.y0 - shared_rect.rect.y0) / shared_rect.scale;
    const int x = static_cast<int>(std::lround(ox)), y = static_cast<int>(std::lround(oy));
    if (std::fabs(ox - x) > 1e-9 || std::fabs(oy - y) > 1e-9 || x < 0 || y < 0 ||
        x + member.width_px > shared.width() || y + member.height_px > shared.height())
        return false;
    PeripheryGrid grid;
    grid.width_px = shared.width();
    grid.height_px = shared.height();
    grid.middle_col = x;
    grid.middle_row = y;
    cropMiddle(shared, grid, member, out);
    return true;
}

}  // namespace

void reduceSharedLayer(const ImageRgba8& shared, const LayerRect& shared_rect,
                       const LayerRect& member_rect, ImageRgba8& out, const HmdProfile& profile,
                       const glm::quat& shared_orientation, const glm::quat& member_orientation) {
    const bool turned = angleBetweenDeg(shared_orientation, member_orientation) > 1e-6;
    if (!turned && cropSharedLayer(shared, shared_rect, member_rect, out))
        return;
    // At one scale, a box of one texel is the bilinear tap the warp takes.
    if ((turned || sameScale(shared_rect, member_rect)) && !shared.empty()) {
        warpSharedLayer(shared, shared_rect, member_rect, out, profile, shared_orientation,
                        member_orientation);
        return;
    }
    PeripheryGrid g;
    g.x0 = shared_rect.rect.x0;
    g.y0 = shared_rect.rect.y0;
    g.scale = shared_rect.scale;
    g.width_px = shared.width();
    g.height_px = shared.height();
    reduceToOuter(shared, g, member_rect, out);
}

nlohmann::json sharePeripheryJson(const SharePeripheryStats& s, double service_ms_per_frame) {
    const uint64_t shared = s.middle.shared + s.outer.shared;
    nlohmann::json bands = nlohmann::json::array();
    for (const SharePeripheryStats::Band& b : s.ssim_by_band)
        bands.push_back({{"layer", b.layer},
                         {"lo_deg", b.lo_deg},
                         {"hi_deg", b.hi_deg},
                         {"ssim_mean", b.ssim_mean},
                         {"ssim_min", b.ssim_min},
                         {"measurements", b.measurements}});
    return {{"mode", s.mode},
            {"min_ssim", s.min_ssim},
            {"band_deg", s.band_deg},
            {"outer_layers_own", s.outer.own},
            {"outer_layers_shared", s.outer.shared},
            {"outer_layers_reused", s.outer.reused},
            {"middle_layers_own", s.middle.own},
            {"middle_layers_shared", s.middle.shared},
            {"middle_layers_reused", s.middle.reused},
            {"measurements", s.measurements},
            {"measurements_failed", s.measurements_failed},
            {"margin_deg_mean", shared ? s.margin_deg_sum / double(shared) : 0.0},
            {"group_texels_per_own",
             s.own_texels ? double(s.group_texels) / double(s.own_texels) : 0.0},
            {"service_ms_per_headset_frame", service_ms_per_frame},
            {"ssim_by_band", std::move(bands)}};
}

SharedPeriphery::SharedPeriphery(SharePeripheryConfig config) : m_config(config) {
    m_stats.mode = sharePeripheryModeName(config.mode);
    m_stats.min_ssim = config.min_ssim;
    m_stats.band_deg = config.band_deg;
}

void SharedPeriphery::join(Id id) {
    std::lock_guard lock(m_mutex);
    m_sessions.try_emplace(id);
}

void SharedPeriphery::noteRequest(Id id, const Pose& pose, const LayerPlan& plan) {
    std::lock_guard lock(m_mutex);
    auto it = m_sessions.find(id);
    if (it == m_sessions.end())
        return;  // gone while its frame was served
    Session& s = it->second;
    if (s.previous) {
        const std::vector<glm::quat> expected = expectedViews(s);
        s.misses_deg.push_back(angleBetweenDeg(expected.back(), pose.orientation));
        if (s.misses_deg.size() > kMissesKept)
            s.misses_deg.pop_front();
    }
    if (s.posed)
        s.previous = s.pose.orientation;
    s.pose = pose;
    s.plan = plan;
    s.posed = true;
}

std::vector<glm::quat> SharedPeriphery::expectedViews(const Session& s) {
    if (!s.previous)
        return {s.pose.orientation};
    // The turn between the two newest requests, once more (a constant angular velocity).
    const glm::quat step = s.pose.orientation * glm::inverse(*s.previous);
    return {s.pose.orientation, glm::normalize(step * s.pose.orientation)};
}

double SharedPeriphery::expectedMissDeg(const Session& s) const {
    if (s.misses_deg.empty())
        return m_config.max_angle_deg;
    return std::min(m_config.max_angle_deg,
                    *std::max_element(s.misses_deg.begin(), s.misses_deg.end()));
}

void SharedPeriphery::forget(Id id) {
    std::lock_guard lock(m_mutex);
    m_sessions.erase(id);
}

size_t SharedPeriphery::slotOf(LayerKind kind, Eye eye) {
    QVR_CHECK(isShareable(kind));
    return (kind == LayerKind::kMiddle ? 0 : 2) + static_cast<size_t>(eye);
}

std::vector<SharedPeriphery::Id> SharedPeriphery::groupOfLocked(Id id, LayerKind kind) const {
    std::vector<Id> ids;
    std::vector<Pose> poses;
    for (const auto& [k, s] : m_sessions) {
        if (!s.posed)
            continue;  // no request yet
        ids.push_back(k);
        poses.push_back(s.pose);
    }
    const LayerPlan& mine = m_sessions.at(id).plan;
    for (const std::vector<size_t>& g : groupByPose(poses, m_config)) {
        std::vector<Id> out;
        for (size_t i : g)
            if (kind == LayerKind::kOuter || ids[i] == id ||
                middleUnionPays(m_sessions.at(ids[i]).plan, mine))
                out.push_back(ids[i]);
        if (std::find(out.begin(), out.end(), id) != out.end())
            return out;
    }
    return {id};
}

bool SharedPeriphery::dueLocked(const Session& s, size_t slot) const {
    return !s.verdict[slot] || s.frames_since_measure[slot] > m_config.remeasure_frames;
}

bool SharedPeriphery::anyTakerLocked(const std::vector<Id>& group, Id id, size_t slot) const {
    return std::any_of(group.begin(), group.end(), [&](Id x) {
        const Session& s = m_sessions.at(x);
        return x != id && (dueLocked(s, slot) || s.verdict[slot].value_or(false));
    });
}

bool SharedPeriphery::usableLocked(const Entry& entry, Id id, Eye eye, LayerKind kind,
                                   const Pose& pose, const LayerPlan& plan,
                                   const HmdProfile& profile, const LayerHoles& holes) const {
    const LayerRect& mine = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
    const LayerRect& theirs = layerOf(entry.shared.plan.eyes[static_cast<size_t>(eye)], kind);
    // A render of its very pose may be taken again (the scene is still: the same texels).
    if ((entry.consumed.contains(id) && !samePose(entry.pose, pose)) ||
        !posesClose(entry.pose, pose, m_config) || theirs.scale > mine.scale + 1e-9 ||
        !theirs.rect.contains(
            rotatedRect(profile, mine.rect, entry.pose.orientation, pose.orientation)))
        return false;
    if (!entry.shared.holes.enabled)
        return true;
    // A hole is a disc about the render's gaze: it must lie inside this headset's own.
    const Gaze& g = entry.shared.plan.gaze;
    const double off_deg = std::hypot(g.x_deg - plan.gaze.x_deg, g.y_deg - plan.gaze.y_deg);
    return layerHoleDeg(profile, entry.shared.plan, eye, kind, entry.shared.holes) + off_deg <=
           layerHoleDeg(profile, plan, eye, kind, holes) + 1e-9;
}

SharedPeriphery::Decision SharedPeriphery::decide(Id id, Eye eye, LayerKind kind, const Pose& pose,
                                                  const LayerPlan& plan, const HmdProfile& profile,
                                                  const LayerHoles& holes) {
    Decision d;
    if (m_config.mode == SharePeripheryMode::kOff)
        return d;
    const size_t slot = slotOf(kind, eye);
    std::shared_ptr<const ImageRgba8> from;
    LayerRect from_rect;
    glm::quat from_orientation;
    {
        std::lock_guard lock(m_mutex);
        auto self = m_sessions.find(id);
        if (self == m_sessions.end() || !self->second.posed)
            return d;  // gone while its frame was served, or not noted
        const std::vector<Id> group = groupOfLocked(id, kind);
        Session& me = self->second;
        // The usable shared render of another headset nearest in orientation (of equals, the
        // newest): headsets that play one motion a few frames apart find the one of their pose,
        // also when the other's newest pose has moved on beyond the group's reach.
        Entry* best = nullptr;
        double best_deg = 0.0;
        for (auto& [other, session] : m_sessions) {
            if (other == id)
                continue;
            for (Entry& entry : session.entries[slot]) {
                if (!usableLocked(entry, id, eye, kind, pose, plan, profile, holes))
                    continue;
                const double deg = angleBetweenDeg(entry.pose.orientation, pose.orientation);
                if (!best || deg < best_deg || (deg == best_deg && entry.serial > best->serial))
                    best = &entry, best_deg = deg;
            }
        }
        me.follows[slot] = best && samePose(best->pose, pose);
        if (!best && group.size() < 2) {
            // Another may come by this pose.
            d.keep = std::any_of(m_sessions.begin(), m_sessions.end(),
                                 [id](const auto& x) { return x.first != id && x.second.posed; });
            return d;
        }
        ++me.frames_since_measure[slot];
        const bool due = dueLocked(me, slot);
        // A render of its very pose (samePose) at its own scale holds the texels its own render
        // would: nothing for the gate to measure, whatever it measured on other renders.
        const bool copy =
            me.follows[slot] && sameScale(layerOf(best->shared.plan.eyes[size_t(eye)], kind),
                                          layerOf(plan.eyes[size_t(eye)], kind));
        if (best && m_config.mode == SharePeripheryMode::kAuto && due && !copy) {
            d.action = Action::kMeasure;
        } else if (best &&
                   (m_config.mode == SharePeripheryMode::kOn || copy || *me.verdict[slot])) {
            d.action = Action::kReuse;
            ++m_stats.of(kind).reused;
        } else if (m_config.mode == SharePeripheryMode::kAuto && !anyTakerLocked(group, id, slot)) {
            // No other member would take a group render (its gate failed, not due); one that
            // comes by this pose would take this render.
            d.keep = true;
            return d;
        } else {
            // Rendered for where the others will look from when they take it, with the largest
            // miss of that expectation as the margin; a member that follows this one's path takes
            // the render of its own pose when it gets there, which this one's view covers.
            std::vector<LayerPlan> plans = {plan};
            MemberViews views{pose.orientation, {{}}};
            double margin_deg = 0.0;
            for (Id other : group) {
                const Session& s = m_sessions.at(other);
                if (other == id || s.follows[slot])
                    continue;
                plans.push_back(s.plan);
                views.of.push_back(expectedViews(s));
                margin_deg = std::max(margin_deg, expectedMissDeg(s));
            }
            d.action = Action::kRenderShared;
            d.shared = sharedLayerPlan(profile, plans, eye, kind, holes, margin_deg, views);
            ++m_stats.of(kind).shared;
            m_stats.margin_deg_sum += margin_deg;
            m_stats.group_texels +=
                uint64_t(layerOf(d.shared.plan.eyes[size_t(eye)], kind).pixels());
            m_stats.own_texels += uint64_t(layerOf(plan.eyes[size_t(eye)], kind).pixels());
            return d;
        }
        best->consumed.insert(id);
        from = best->image;
        from_rect = layerOf(best->shared.plan.eyes[static_cast<size_t>(eye)], kind);
        from_orientation = best->pose.orientation;
    }
    reduceSharedLayer(*from, from_rect, layerOf(plan.eyes[static_cast<size_t>(eye)], kind), d.image,
                      profile, from_orientation, pose.orientation);
    return d;
}

void SharedPeriphery::store(Id renderer, Eye eye, LayerKind kind, const Pose& pose,
                            const SharedLayer& shared, ImageRgba8 image) {
    std::lock_guard lock(m_mutex);
    auto it = m_sessions.find(renderer);
    if (it == m_sessions.end())
        return;
    std::deque<Entry>& kept = it->second.entries[slotOf(kind, eye)];
    kept.push_back(
        Entry{pose, shared, std::make_shared<const ImageRgba8>(std::move(image)), {}, ++m_serial});
    while (kept.size() > kRendersKept)
        kept.pop_front();
}

void SharedPeriphery::measured(Id id, Eye eye, LayerKind kind, const std::vector<BandSsim>& bands) {
    std::lock_guard lock(m_mutex);
    const bool pass = bandsPass(bands, m_config.min_ssim);
    ++m_stats.measurements;
    m_stats.measurements_failed += pass ? 0 : 1;
    auto it = m_sessions.find(id);
    if (it != m_sessions.end()) {
        it->second.verdict[slotOf(kind, eye)] = pass;
        it->second.frames_since_measure[slotOf(kind, eye)] = 0;
    }
    const std::string layer = layerName(kind);
    auto& v = m_stats.ssim_by_band;
    for (const BandSsim& b : bands) {
        auto key = [](const SharePeripheryStats::Band& y) { return std::tie(y.layer, y.lo_deg); };
        const SharePeripheryStats::Band probe{layer, b.lo_deg, b.hi_deg, 0.0, 1.0, 0};
        auto x = std::lower_bound(v.begin(), v.end(), probe,
                                  [&](const auto& l, const auto& r) { return key(l) < key(r); });
        if (x == v.end() || key(*x) != key(probe))
            x = v.insert(x, probe);
        ++x->measurements;
        x->ssim_mean += (b.ssim - x->ssim_mean) / double(x->measurements);
        x->ssim_min = std::min(x->ssim_min, b.ssim);
    }
}

void SharedPeriphery::countOwn(LayerKind kind) {
    std::lock_guard lock(m_mutex);
    ++m_stats.of(kind).own;
}

SharePeripheryStats SharedPeriphery::stats() const {
    std::lock_guard lock(m_mutex);
    return m_stats;
}

}  // namespace qvr::runtime
