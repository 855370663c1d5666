// `qvr run` as one call: its plan's calibration, the designs run (design_runs.h), predicted
// (prediction.h) and reported (run_report.h) into the plan's output folder.
#pragma once

#include <string>
#include <vector>

#include "qvr/core/design.h"
#include "qvr/experiment/run_plan.h"
#include "qvr/experiment/run_report.h"
#include "qvr/foveation/hmd_profile.h"

namespace qvr::experiment {

// The console's closing lines: the headline ratios, each prediction's errors, the machine's
// speed, the notes and what was written.
void printRunSummary(const RunOutcome& outcome, const std::string& out);
// The exit status: 130 interrupted, 1 when a design never showed the server's layers, else 0
// (with a message on stderr for either).
int runExitStatus(const RunOutcome& outcome, const std::string& out);

// Runs `designs` as the plan says, once its options are checked. Returns the exit status (2 for
// bad input found on the way: the traces, the calibration file, --headset-share).
int runExperiment(const RunOptions& plan, const std::vector<DesignSpec>& designs,
                  const HmdProfile& profile);

// `qvr run-headset` (internal): one of `qvr run --headsets N`'s other headsets, its settings as
// a JSON line on stdin (headset_child.h). Returns the exit status.
int runHeadsetChild();

}  // namespace qvr::experiment
