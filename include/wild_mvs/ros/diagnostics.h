// Copyright wild_mvs authors. Diagnostics pieces both nodes use: an event
// rate that tolerates quiet spells, and the drop counts as status values.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <diagnostic_updater/update_functions.h>

#include <string>
#include <utility>

#include "wild_mvs/stream/drop_counter.h"

namespace wild_mvs {
namespace ros1 {

// A diagnostic_updater::FrequencyStatus (the event rate over the last
// `window` diagnostics updates, judged against [min_hz, max_hz]; 0 and inf
// = not judged) that reports a window without events as `quiet_level` with
// `quiet_message` instead of ERROR: no depth map for a while is normal when
// no new keyframe came.
class RateStatus : private std::pair<double, double>,
                   public diagnostic_updater::FrequencyStatus {
 public:
  RateStatus(const std::string& name, double min_hz, double max_hz, int window,
             unsigned char quiet_level, std::string quiet_message);
  void run(diagnostic_updater::DiagnosticStatusWrapper& stat) override;

 private:
  unsigned char quiet_level_;
  std::string quiet_message_;
};

// The drop counts as status values: "<what> dropped" (total), "<what>
// dropped recently" (within the window), "drop window s", and
// "dropped: <reason>" per reason (totals).
void AddDropValues(const DropCounter& drops, const std::string& what,
                   diagnostic_updater::DiagnosticStatusWrapper& stat);

// Counts one dropped input of `reason` ("<topic>: <problem>") in `drops`
// and, when the counter lets it through (one message per reason per
// `throttle` s), logs it with ROS_ERROR: "<ns>: dropped: <reason>: <detail>
// (<n> so far; ...)".
void LogDrop(DropCounter* drops, const std::string& ns,
             const std::string& reason, const std::string& detail,
             double throttle);

}  // namespace ros1
}  // namespace wild_mvs
