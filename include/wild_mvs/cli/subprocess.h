// Copyright wild_mvs authors. Running an external program (the `photos`
// command's colmap stages) with its output in a log file.
#pragma once

#include <string>
#include <vector>

namespace wild_mvs {
namespace cli {

// The executable `name` resolves to: `name` itself when it contains a '/'
// (and is executable), else the first executable PATH entry; "" when none.
std::string FindExecutable(const std::string& name);

struct ProcessResult {
  int exit_code = -1;  // 128 + signal when killed by a signal
  double seconds = 0;
  double cpu_seconds = 0;  // user + system of the process and its children
};

// Runs argv[0] (a path) with argv, stdin from /dev/null, stdout and stderr
// appended to `log_path` (created), and waits. Throws Error when the
// process cannot be started or the log cannot be opened.
ProcessResult RunProcess(const std::vector<std::string>& argv,
                         const std::string& log_path);

// The last `lines` lines of a text file ("" when unreadable).
std::string TailOfFile(const std::string& path, int lines);

}  // namespace cli
}  // namespace wild_mvs
