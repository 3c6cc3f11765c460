// Copyright wild_mvs authors.
#include "wild_mvs/ros/diagnostics.h"

namespace wild_mvs {
namespace ros1 {

RateStatus::RateStatus(const std::string& name, double min_hz, double max_hz,
                       int window, unsigned char quiet_level,
                       std::string quiet_message)
    : std::pair<double, double>(min_hz, max_hz),
      diagnostic_updater::FrequencyStatus(
          diagnostic_updater::FrequencyStatusParam(&first, &second, 0.1,
                                                   window),
          name),
      quiet_level_(quiet_level),
      quiet_message_(std::move(quiet_message)) {}

void RateStatus::run(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  diagnostic_updater::FrequencyStatus::run(stat);
  // FrequencyStatus says ERROR only for a window without events.
  if (stat.level == diagnostic_msgs::DiagnosticStatus::ERROR)
    stat.summary(quiet_level_, quiet_message_);
}

void AddDropValues(const DropCounter& drops, const std::string& what,
                   diagnostic_updater::DiagnosticStatusWrapper& stat) {
  stat.add(what + " dropped", drops.Total());
  stat.add(what + " dropped recently", drops.RecentTotal());
  stat.add("drop window s", drops.window());
  for (const auto& [reason, n] : drops.Counts())
    stat.add("dropped: " + reason, n);
}

}  // namespace ros1
}  // namespace wild_mvs
