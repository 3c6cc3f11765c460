// Copyright wild_mvs authors. Depth metrics pooled over views (tests that
// compare whole runs, e.g. live against offline).
#pragma once

#include "wild_mvs/core/metrics.h"

namespace wild_mvs {
namespace testing {

// Sums of EvaluateDepth results with the default relative thresholds
// (1 %, 2 %, 5 %): ground-truth pixels with an estimate, estimates within
// 1 % and off by more than 5 %.
struct PooledDepthMetrics {
  double gt = 0, evaluated = 0, in1 = 0, off5 = 0;
  void Add(const DepthMetrics& m) {
    gt += m.gt_valid;
    evaluated += m.evaluated;
    in1 += m.relative_accuracy[0] * m.evaluated;
    off5 += (1 - m.relative_accuracy[2]) * m.evaluated;
  }
  double coverage() const { return gt > 0 ? evaluated / gt : 0; }
  double within1() const { return evaluated > 0 ? in1 / evaluated : 0; }
  double off5pc() const { return evaluated > 0 ? off5 / evaluated : 0; }
};

}  // namespace testing
}  // namespace wild_mvs
