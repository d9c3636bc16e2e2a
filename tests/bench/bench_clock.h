// The clock the benchmarks measure with.
#pragma once

#include <time.h>

namespace tod::bench {

// CPU time of the calling thread in milliseconds: the machine is shared, and wall time would
// largely measure the neighbours.
inline double ThreadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace tod::bench
