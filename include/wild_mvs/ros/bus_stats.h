// Copyright wild_mvs authors. Messages that roscpp itself dropped from a
// subscription's queue (the queue_size of NodeHandle::subscribe was full
// when a message arrived): roscpp counts them per publisher link and shows
// them only in its XML-RPC getBusStats; the nodes add them to their drop
// counts so that no drop goes uncounted.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "wild_mvs/stream/drop_counter.h"

namespace wild_mvs {
namespace ros1 {

// roscpp's drop count of every subscription of this process, by resolved
// topic name (summed over its publisher links).
std::map<std::string, uint64_t> RoscppQueueDrops();

// Adds to `drops` the roscpp queue drops of `topics` (resolved names) since
// the last call, under "<topic>: roscpp queue full (<hint>)"; the hint says
// what to do, e.g. "raise ~input_queue_size".
class RoscppDropWatch {
 public:
  void Update(const std::map<std::string, std::string>& topic_to_hint,
              DropCounter* drops);

 private:
  std::map<std::string, uint64_t> seen_;
};

}  // namespace ros1
}  // namespace wild_mvs
