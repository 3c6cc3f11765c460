// Copyright wild_mvs authors.
#include "wild_mvs/core/stats.h"

#include <sys/resource.h>

namespace wild_mvs {

double CpuSeconds() {
  rusage u;
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec +
         1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double PeakRssMb() {
  rusage u;
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return u.ru_maxrss / 1024.0;  // Linux: kilobytes
}

}  // namespace wild_mvs
