// `qvr calibrate`'s engine (calibration.h): the micro-benchmarks in order, each part alone on
// one pinned core, between three speed probes; then the fit, the link and the co-running.
#include "qvr/experiment/calibration.h"

#include <chrono>
#include <memory>

#include <fmt/format.h>

#include "calibration_bench.h"
#include "qvr/experiment/calibration_fit.h"
#include "qvr/experiment/host.h"

namespace qvr::experiment {

namespace {

// The machine's speed while it is measured: a probe after the renderer's warm-up, one after
// the layers, one at the end (SpeedProbe; their mean is the hardware file's speed reference).
// A probe that cannot run leaves the file without a reference (no run probes against it), not
// the costs unmeasured.
class SpeedProbes {
public:
    SpeedProbes(const CalibrationBench& bench, Calibration& cal)
        : m_bench(bench), m_cal(cal), m_probe(SpeedProbe::make(bench.options)) {
        m_cal.speed_note = m_probe ? "" : m_probe.error();
    }
    void take() {
        if (!m_cal.speed_note.empty())
            return;
        auto sample = (*m_probe)->measure();
        if (!sample) {
            m_cal.speed_note = sample.error();
            m_cal.speed_probes.clear();
            return;
        }
        m_cal.speed_probes.push_back(*sample);
        m_bench.log(
            fmt::format("  speed probe {}: headset frame {:.2f} ms, server frame {:.2f} ms\n",
                        m_cal.speed_probes.size(), sample->headset_ms, sample->server_ms));
    }
    // The reference: the probes' mean, under this calibration's key.
    void setReference() {
        if (!m_cal.speed_note.empty()) {
            m_cal.speed_note = "no speed reference: " + m_cal.speed_note;
            m_bench.log("  " + m_cal.speed_note + "\n");
            return;
        }
        const SpeedSample ref = meanSpeed(m_cal.speed_probes);
        m_cal.costs.speed_reference_headset_ms = ref.headset_ms;
        m_cal.costs.speed_reference_server_ms = ref.server_ms;
        m_cal.costs.speed_reference_key = calibrationCacheKey(m_bench.options);
        m_bench.log(
            fmt::format("  speed reference: headset frame {:.2f} ms, server frame {:.2f} ms "
                        "(mean of {} probes: {})\n",
                        ref.headset_ms, ref.server_ms, m_cal.speed_probes.size(),
                        speedProbesText(m_cal.speed_probes)));
    }

private:
    const CalibrationBench& m_bench;
    Calibration& m_cal;
    Expected<std::unique_ptr<SpeedProbe>> m_probe;
};

// The micro-benchmarks after the renderer's warm-up, in order, into `samples`, the first and
// second speed probes among them.
Status measureParts(CalibrationBench& b, SpeedProbes& speed, CalibrationSamples& samples,
                    Calibration& cal) {
    speed.take();
    if (auto st = measureLayerSequences(b, samples); !st)
        return st;
    speed.take();
    if (auto st = measureFullFrames(b, samples); !st)
        return st;
    auto codec_by_e1 = measureLayerCodec(b, samples);
    if (!codec_by_e1)
        return makeError(codec_by_e1.error());
    cal.codec_by_e1 = std::move(*codec_by_e1);
    copyCanvasPolicy(b.codec, cal.costs);
    if (auto st = measureWholeFrameCodec(b, samples); !st)
        return st;
    return measureDecodes(b, samples);
}

}  // namespace

Expected<Calibration> runCalibration(const CalibrateOptions& o) {
    const auto t_start = CalibrationClock::now();
    Calibration cal;
    cal.load_avg_before = loadAverage1();
    cal.machine = machineDescription();
    cal.date = utcNow();
    auto bench = makeCalibrationBench(o);
    if (!bench)
        return makeError(bench.error());
    CalibrationBench& b = **bench;
    CalibrationSamples samples;
    measureDecision(b, samples);
    measurePlan(b, samples);
    if (auto st = warmUpRenderer(b); !st)
        return makeError(st.error());
    SpeedProbes speed(b, cal);
    if (auto st = measureParts(b, speed, samples, cal); !st)
        return makeError(st.error());
    fitCalibration(samples, cal);
    describeLinks(cal);
    if (auto st = measureCoRun(b, cal); !st)
        return makeError(st.error());
    speed.take();
    speed.setReference();
    cal.seconds = std::chrono::duration<double>(CalibrationClock::now() - t_start).count();
    return cal;
}

}  // namespace qvr::experiment
