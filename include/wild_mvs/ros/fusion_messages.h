// Copyright wild_mvs authors. The fusion node's messages around the
// ROS-free FusionSession: a DepthView decoded into a FusionView, and the
// node's diagnostics.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <wild_mvs/DepthView.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "wild_mvs/ros/params.h"
#include "wild_mvs/stream/drop_counter.h"
#include "wild_mvs/stream/fusion_session.h"
#include "wild_mvs/stream/keyframe_ledger.h"

namespace wild_mvs {
namespace ros1 {

// The view of a DepthView (depth map, image in linear RGB when it has the
// map's size, keyframe id, session, stamps; `arrived` = now). Throws Error
// for an invalid message.
FusionView FusionViewFromMsg(const wild_mvs::DepthView& msg);

void FillFusionDiagnostics(const FusionSessionStats& s, uint64_t received,
                           size_t queued, const DropCounter& drops,
                           diagnostic_updater::DiagnosticStatusWrapper& stat);

// A stamp in ns as "seconds.nanoseconds" (exact, for messages).
std::string StampText(uint64_t stamp_ns);

// The keyframe ledger's values; WARN (naming the first stamps) while a
// keyframe a selector announced has no depth view after
// keyframe_missing_after or one was reconstructed twice.
void AddKeyframeLedgerValues(const KeyframeLedger::Report& r,
                             diagnostic_updater::DiagnosticStatusWrapper& stat);

}  // namespace ros1
}  // namespace wild_mvs
