// Copyright wild_mvs authors. Small statistics and process measurements
// shared by the core, the command-line tool and the benchmarks.
#pragma once

#include <algorithm>
#include <vector>

namespace wild_mvs {

// The upper median of v (element v.size() / 2 in sorted order; no mean of
// the two middle values); 0 when v is empty. Takes v by value (reorders the
// copy); pass std::move(v) when v is no longer needed.
template <typename T>
double Median(std::vector<T> v) {
  if (v.empty()) return 0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return static_cast<double>(v[m]);
}

// Process CPU time (user + system) in seconds, all threads; 0 when unknown.
double CpuSeconds();

// Peak resident set size of the process in MB; 0 when unknown.
double PeakRssMb();

// Returns the allocator's free memory to the system (glibc: malloc_trim,
// every arena). Between stages: memory a stage's worker threads freed stays
// in their arenas otherwise, where the next stage's (main-thread)
// allocations cannot reuse it, and adds to the peak. No-op elsewhere.
void ReleaseFreeMemory();

// Makes the allocator map every block of 128 KB or more on its own and
// unmap it when freed (glibc: M_MMAP_THRESHOLD fixed at 128 KB). By
// default glibc raises that threshold to the size of each mapped block
// freed (up to 32 MB), so after the first freed image or depth map such
// buffers come from the heap, where the holes they leave between small
// long-lived blocks (the fusion's hash nodes, pending samples) stay
// resident: measured on `wild_mvs fuse` of 100 / 250 synthetic views, peak
// RSS 195 / 219 MB by default, 178 / 189 MB with the fixed threshold
// (docs/SCALE.md). For a process's main() only (it sets process-wide
// allocator state); no-op elsewhere.
void UseFixedMmapThreshold();

}  // namespace wild_mvs
