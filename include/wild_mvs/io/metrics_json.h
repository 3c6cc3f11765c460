// Copyright wild_mvs authors. JSON of the evaluation metrics (core/metrics.h)
// for `wild_mvs eval --json`: one object, no trailing newline; non-finite
// numbers are null.
#pragma once

#include <string>

#include "wild_mvs/core/metrics.h"

namespace wild_mvs {

std::string DepthMetricsJson(const DepthMetrics& metrics);
std::string CloudMetricsJson(const CloudMetrics& metrics);

}  // namespace wild_mvs
