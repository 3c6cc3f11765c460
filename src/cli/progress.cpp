// Copyright wild_mvs authors.
#include "wild_mvs/cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace wild_mvs {
namespace cli {

bool StderrIsTerminal() {
  const char* term = std::getenv("TERM");
  if (term && std::strcmp(term, "dumb") == 0) return false;
  return isatty(fileno(stderr)) == 1;
}

std::string Progress::FormatDuration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long long t = std::llround(s);
  char buf[32];
  if (t < 60) {
    std::snprintf(buf, sizeof(buf), "%llds", t);
  } else if (t < 3600) {
    std::snprintf(buf, sizeof(buf), "%lldm%02llds", t / 60, t % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%lldh%02lldm", t / 3600, (t % 3600) / 60);
  }
  return buf;
}

Progress::Progress(std::string stage, int total, std::ostream& os,
                   bool interactive)
    : stage_(std::move(stage)),
      total_(std::max(total, 0)),
      os_(os),
      interactive_(interactive) {
  item_start_ = last_draw_ = Clock::now();
}

Progress::~Progress() { Finish(); }

void Progress::Begin(const std::string& label) {
  std::lock_guard<std::mutex> lock(mutex_);
  label_ = label;
  fraction_ = 0;
  item_start_ = Clock::now();
  DrawLocked(true);
}

void Progress::Fraction(double f) {
  std::lock_guard<std::mutex> lock(mutex_);
  fraction_ = std::clamp(f, 0.0, 1.0);
  DrawLocked(false);
}

void Progress::End(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  work_seconds_ +=
      std::chrono::duration<double>(Clock::now() - item_start_).count();
  ++done_;
  ++worked_;
  fraction_ = 0;
  label_.clear();
  ClearLocked();
  if (!message.empty()) os_ << message << "\n";
  DrawLocked(true);
}

void Progress::Skip(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++done_;
  ClearLocked();
  if (!message.empty()) os_ << message << "\n";
  DrawLocked(true);
}

void Progress::Print(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  ClearLocked();
  os_ << message << "\n";
  DrawLocked(true);
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  ClearLocked();
  finished_ = true;
  os_.flush();
}

double Progress::EtaLocked() const {
  // Mean time of the worked items (plus the running one's share).
  const double running =
      std::chrono::duration<double>(Clock::now() - item_start_).count();
  const double units = worked_ + (label_.empty() ? 0.0 : fraction_);
  if (units < 0.05) return -1;
  const double per_item =
      (work_seconds_ + (label_.empty() ? 0.0 : running)) / units;
  const double remaining =
      std::max(0.0, total_ - done_ - (label_.empty() ? 0.0 : fraction_));
  return per_item * remaining;
}

void Progress::ClearLocked() {
  if (interactive_ && drawn_) {
    os_ << "\r\033[K";
    drawn_ = false;
  }
}

void Progress::DrawLocked(bool force) {
  if (!interactive_ || finished_) return;
  const auto now = Clock::now();
  if (!force && now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = now;
  const int width = 24;
  const double f =
      total_ > 0 ? std::min(1.0, (done_ + fraction_) / total_) : 1.0;
  const int filled = static_cast<int>(f * width);
  std::ostringstream line;
  line << "\r\033[K" << stage_ << " [" << std::string(filled, '#')
       << std::string(width - filled, '.') << "] " << done_ << "/" << total_;
  if (!label_.empty()) {
    line << " " << label_ << " " << static_cast<int>(fraction_ * 100) << "%";
  }
  const double eta = EtaLocked();
  if (eta >= 0 && done_ < total_) line << "  ETA " << FormatDuration(eta);
  os_ << line.str() << std::flush;
  drawn_ = true;
}

}  // namespace cli
}  // namespace wild_mvs
