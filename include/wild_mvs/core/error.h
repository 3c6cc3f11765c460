// Copyright wild_mvs authors. Error type shared by every layer.
//
// Every recoverable problem (bad input file, bad option value, impossible
// request) is reported by throwing wild_mvs::Error with a message that names
// the file / line / topic / option and the problem. Tools turn it into a
// non-zero exit, ROS nodes into a throttled ROS_ERROR and a dropped message.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace wild_mvs {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

// A computation stopped because its caller asked (a node shutting down).
class Cancelled : public Error {
 public:
  explicit Cancelled(const std::string& what) : Error(what) {}
};

// Builds a message from streamable parts: throw Error(Msg("x = ", x)).
template <typename... Args>
std::string Msg(const Args&... args) {
  std::ostringstream os;
  (os << ... << args);
  return os.str();
}

// Throws Error(Msg(args...)) unless cond holds. For option checks:
//   Require(ncc_threshold >= -1 && ncc_threshold <= 1,
//           "mvs.ncc_threshold = ", ncc_threshold, " must be in [-1, 1]");
template <typename... Args>
void Require(bool cond, const Args&... args) {
  if (!cond) throw Error(Msg(args...));
}

}  // namespace wild_mvs
