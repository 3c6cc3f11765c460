// Copyright wild_mvs authors.
#include "wild_mvs/ros/fusion_messages.h"

#include <chrono>
#include <cstdio>

#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/diagnostics.h"

namespace wild_mvs {
namespace ros1 {

FusionView FusionViewFromMsg(const wild_mvs::DepthView& msg) {
  FusionView view;
  view.map = DepthMapFromDepthView(msg);
  if (!msg.image.data.empty()) {
    view.image = ImageToLinearRgb(msg.image, true);
    if (view.image.size() != view.map.depth.size()) view.image.release();
  }
  view.keyframe_id = msg.keyframe_id;
  view.session_ns = msg.session.toNSec();
  for (const ros::Time& s : msg.neighbor_stamps)
    view.neighbor_stamps_ns.push_back(s.toNSec());
  view.stamp_ns = msg.header.stamp.toNSec();
  view.revision = static_cast<int>(msg.revision);
  view.final_revision = msg.final_revision;
  view.arrived = std::chrono::steady_clock::now();
  return view;
}

void FillFusionDiagnostics(const FusionSessionStats& s, uint64_t received,
                           size_t queued, const DropCounter& drops,
                           diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const uint64_t recent = drops.RecentTotal();
  if (recent > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%lu depth views dropped in the last %.0f s",
                  static_cast<unsigned long>(recent), drops.window());
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
  stat.add("views received", received);
  stat.add("input queue length", queued);
  stat.add("views waiting for order", s.waiting);
  stat.add("views fused", s.fused);
  stat.add("revisions replaced", s.revisions_replaced);
  stat.add("revisions ignored", s.revisions_ignored);
  stat.add("points", s.fusion.points);
  stat.add("pending samples", s.fusion.pending);
  stat.add("fusion bytes", s.fusion_bytes);
  stat.add("held depth map MB", s.held_mb);
  stat.add("depth maps spilled", s.spilled);
  stat.add("last seconds per view", s.last_fuse_seconds);
  stat.add("resets", s.resets);
  stat.add("depth sessions", s.sessions);
  stat.add("session clouds saved", s.session_saves);
  AddDropValues(drops, "views", stat);
}

std::string StampText(uint64_t stamp_ns) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%llu.%09llu",
                static_cast<unsigned long long>(stamp_ns / 1000000000ull),
                static_cast<unsigned long long>(stamp_ns % 1000000000ull));
  return buf;
}

void AddKeyframeLedgerValues(
    const KeyframeLedger::Report& r,
    diagnostic_updater::DiagnosticStatusWrapper& stat) {
  auto list = [](const std::vector<KeyframeLedger::Key>& keys) {
    std::string text;
    for (const KeyframeLedger::Key& k : keys)
      text += (text.empty() ? "" : " ") + StampText(k.second);
    return text;
  };
  stat.add("keyframes announced", r.announced);
  stat.add("keyframes with a depth view", r.done);
  stat.add("keyframes missing", r.missing);
  stat.add("keyframes done twice", r.twice);
  if (r.missing > 0) {
    stat.add("keyframes missing (first stamps)", list(r.missing_keys));
    stat.mergeSummaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                       "%lu keyframes without a depth view",
                       static_cast<unsigned long>(r.missing));
  }
  if (r.twice > 0) {
    stat.add("keyframes done twice (first stamps)", list(r.twice_keys));
    stat.mergeSummaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                       "%lu keyframes reconstructed twice",
                       static_cast<unsigned long>(r.twice));
  }
}

}  // namespace ros1
}  // namespace wild_mvs
