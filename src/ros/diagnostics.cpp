// Copyright wild_mvs authors.
#include "wild_mvs/ros/diagnostics.h"

#include <ros/console.h>

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

void LogDrop(DropCounter* drops, const std::string& ns,
             const std::string& reason, const std::string& detail,
             double throttle) {
  uint64_t n = 0;
  if (!drops->Count(reason, &n)) return;
  ROS_ERROR(
      "%s: dropped: %s%s%s (%lu so far; throttled to one message per %.0f s "
      "per problem)",
      ns.c_str(), reason.c_str(), detail.empty() ? "" : ": ", detail.c_str(),
      static_cast<unsigned long>(n), throttle);
}

}  // namespace ros1
}  // namespace wild_mvs
