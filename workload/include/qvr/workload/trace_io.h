// Reading and writing workload traces: JSON lines, one header object then one object per
// frame. The grammar is in docs/WORKLOAD_FORMAT.md; the reader treats the file as untrusted.
#pragma once

#include <iosfwd>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/workload/workload.h"

namespace qvr {

Expected<WorkloadTrace> readWorkloadTrace(std::istream& in, const std::string& source_name);
Expected<WorkloadTrace> loadWorkloadTrace(const std::string& path);

// Streaming writer: the header first, then frames as they are produced, flushed per frame so an
// interrupted recording keeps what it wrote.
class WorkloadTraceWriter {
public:
    explicit WorkloadTraceWriter(std::ostream& out);
    void writeHeader(const WorkloadHeader& header);
    void writeFrame(const WorkloadFrame& frame);

private:
    std::ostream& m_out;
    const WorkloadHeader* m_header = nullptr;
    WorkloadHeader m_header_copy;
};

Status saveWorkloadTrace(const WorkloadTrace& trace, const std::string& path);

}  // namespace qvr
