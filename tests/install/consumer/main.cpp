// An engine's use of an installed qvr: LIWC sizes the fovea for a workload frame, then UCA
// composes a frame of layers planned at that size for a display pose. Exits 0 only when both
// give a plausible answer.
#include <array>
#include <cstdio>

#include <qvr/compose/uca.h>
#include <qvr/controller/liwc.h>
#include <qvr/foveation/layer_plan.h>
#include <qvr/workload/synthetic.h>

namespace {

qvr::ImageRgba8 solid(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
    qvr::ImageRgba8 img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            img.at(x, y, 0) = r;
            img.at(x, y, 1) = g;
            img.at(x, y, 2) = b;
            img.at(x, y, 3) = 255;
        }
    return img;
}

}  // namespace

int main() {
    qvr::HmdProfile profile = qvr::defaultHmdProfile();
    profile.width_px = 320;
    profile.height_px = 360;

    qvr::SyntheticSpec spec = qvr::defaultSyntheticSpec();
    spec.profile = profile;
    spec.frames = 4;
    const qvr::WorkloadTrace trace = qvr::generateSyntheticWorkload(spec);
    qvr::LiwcPolicy liwc(trace.header);
    const qvr::Decision d = liwc.decide(trace.frames.at(0));
    if (!(d.e1_deg >= 1.0 && d.e1_deg <= 90.0)) {
        std::fprintf(stderr, "LIWC chose e1 = %f deg\n", d.e1_deg);
        return 1;
    }

    qvr::LayerFrame frame;
    frame.plan = qvr::LayerPlanner(profile).plan({0.0, 0.0}, d.e1_deg);
    for (int eye = 0; eye < 2; ++eye) {
        const qvr::EyeLayers& l = frame.plan.eyes[eye];
        frame.eyes[eye].fovea = solid(l.fovea.width_px, l.fovea.height_px, 200, 40, 40);
        if (!l.middle.empty())
            frame.eyes[eye].middle = solid(l.middle.width_px, l.middle.height_px, 40, 200, 40);
        if (!l.outer.empty())
            frame.eyes[eye].outer = solid(l.outer.width_px, l.outer.height_px, 40, 40, 200);
    }
    qvr::Compositor uca(profile);
    std::array<qvr::ImageRgba8, 2> display;
    auto report = uca.compose(frame, qvr::Pose{}, display);
    if (!report) {
        std::fprintf(stderr, "UCA: %s\n", report.error().c_str());
        return 1;
    }
    // Looking straight ahead, the display's centre shows the fovea layer.
    const int cx = profile.width_px / 2, cy = profile.height_px / 2;
    if (display[0].width() != profile.width_px || display[0].at(cx, cy, 0) != 200 ||
        display[0].at(cx, cy, 1) != 40) {
        std::fprintf(stderr, "UCA: centre pixel (%d, %d, %d) is not the fovea's\n",
                     display[0].at(cx, cy, 0), display[0].at(cx, cy, 1), display[0].at(cx, cy, 2));
        return 1;
    }
    std::printf("qvr_consumer: LIWC e1 %.1f deg; UCA %dx%d per eye, %lld tiles\n", d.e1_deg,
                display[0].width(), display[0].height(),
                static_cast<long long>(report->tiles.total()));
    return 0;
}
