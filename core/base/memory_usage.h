// The process's resident memory, for the memory figures of `tod train` and `tod bench`.
#pragma once

namespace tod {

// Peak resident set size of this process so far, in MiB: VmHWM of /proc/self/status, the high
// water mark of this program's own address space. (getrusage's ru_maxrss is not used: after exec
// it also counts the peak of the process that started this one, e.g. a large test harness.)
// Falls back to ru_maxrss where /proc is not readable.
double PeakRssMb();

}  // namespace tod
