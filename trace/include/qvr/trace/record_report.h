// The lines `qvr trace record` prints about a recording: what it records, how far it is, and
// what it wrote.
#pragma once

#include <string>

#include "qvr/trace/recorder.h"

namespace qvr {

// The scene (triangles, batches, spawn points), the display, the frame count and the renderer.
std::string recordingHeadline(const RecordOptions& options, const RecordInputs& inputs,
                              const std::string& renderer);

// Progress after p.frame frames: on a terminal one line rewritten in place ("\r..."), in a log a
// line every 10 frames and at the end; empty when no line is due.
std::string recordProgressLine(const RecordProgress& p, bool terminal);

// The closing line of a recording that was not stopped early.
std::string recordingDoneLine(const RecordResult& result, const std::string& out_path);

}  // namespace qvr
