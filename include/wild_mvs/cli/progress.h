// Copyright wild_mvs authors. Progress reporting for long CLI stages.
//
// On a terminal: one self-updating line "[#####.....] 5/16 name 31% ETA 1m20s"
// with messages printed above it. Elsewhere (logs, CI, pipes): only the
// messages, one plain line each, so logs stay readable. Thread-safe: workers
// may report fractions of the current item.
#pragma once

#include <chrono>
#include <mutex>
#include <ostream>
#include <string>

namespace wild_mvs {
namespace cli {

class Progress {
 public:
  // `total` items; `interactive` draws the bar (use IsTerminal(stderr)).
  Progress(std::string stage, int total, std::ostream& os, bool interactive);
  ~Progress();

  // Starts item `label`; counts as work for the ETA.
  void Begin(const std::string& label);
  // Fraction [0, 1] of the current item (from worker threads).
  void Fraction(double f);
  // Finishes the current item and prints `message` as a line.
  void End(const std::string& message);
  // An item that needed no work (e.g. resumed): counted, excluded from the
  // ETA's rate.
  void Skip(const std::string& message);
  // A line of text that keeps the bar intact.
  void Print(const std::string& message);
  // Clears the bar line (also done by the destructor).
  void Finish();

  // Formats seconds as "42s", "3m05s", "1h02m".
  static std::string FormatDuration(double seconds);

 private:
  void DrawLocked(bool force);
  void ClearLocked();
  double EtaLocked() const;

  using Clock = std::chrono::steady_clock;
  std::string stage_;
  int total_, done_ = 0, worked_ = 0;
  std::ostream& os_;
  bool interactive_, drawn_ = false, finished_ = false;
  std::string label_;
  double fraction_ = 0;
  double work_seconds_ = 0;  // time spent on worked items
  Clock::time_point item_start_, last_draw_;
  std::mutex mutex_;
};

// True when stderr is a terminal (and TERM is not "dumb").
bool StderrIsTerminal();

}  // namespace cli
}  // namespace wild_mvs
