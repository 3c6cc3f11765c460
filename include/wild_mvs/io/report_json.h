// Copyright wild_mvs authors. JSON text of the per-view reconstruction
// report (OUT/log/<stem>.json): written by the I/O layer, not the core.
#pragma once

#include <string>

#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// One JSON object: the neighbours (by name, "?" for an index outside the
// scene) with their scores and scales, the working scale and resolution,
// the seed, sample and visit counts, the fallback notes and the times.
// Non-finite numbers are written as null.
std::string ViewReportJson(const ViewReport& report, const Scene& scene);

}  // namespace wild_mvs
