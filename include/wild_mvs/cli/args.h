// Copyright wild_mvs authors. Command-line parsing for the wild_mvs
// subcommands.
//
// Each subcommand declares its flags; `--name VALUE`, `--name=VALUE` and
// boolean `--name` are accepted, `--` ends the flags. Flags that are not
// declared are looked up in an optional OptionSet (the core's options, e.g.
// `--mvs.ncc_threshold 0.4`) and collected in command-line order. Anything
// else is a UsageError naming the flag.
#pragma once

#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace cli {

// A mistake on the command line (exit status 2 instead of 1).
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& what) : Error(what) {}
};

struct FlagSpec {
  std::string name;     // without the leading "--"
  std::string metavar;  // "" = boolean switch; else the value's name
  std::string help;
  // When set, the flag is another name for this option of the OptionSet
  // (e.g. --threads for run.threads): its value joins core_assignments().
  std::string alias_of;
};

struct CommandSpec {
  std::string name;                      // "reconstruct"
  std::string usage;                     // "DATASET OUT [options]"
  std::string summary;                   // one paragraph
  std::vector<std::string> positionals;  // names, for the usage line
  int min_positionals = 0, max_positionals = 0;
  std::vector<FlagSpec> flags;
  std::string epilog;  // printed after the flags (examples, notes)
};

class Args {
 public:
  // Parses argv (without the program and command names). With `core`, flags
  // that name one of its options are collected in core_assignments().
  // Throws UsageError. `--help`/`-h` sets help() and stops checking the
  // positional count.
  Args(const CommandSpec& spec, const std::vector<std::string>& argv,
       const OptionSet* core = nullptr);

  bool help() const { return help_; }
  const std::vector<std::string>& positionals() const { return positionals_; }
  const std::string& positional(size_t i) const { return positionals_.at(i); }
  bool Has(const std::string& flag) const { return values_.count(flag) > 0; }
  // Value of a declared flag, or `fallback` when it is absent.
  std::string Get(const std::string& flag,
                  const std::string& fallback = "") const;
  int GetInt(const std::string& flag, int fallback, int min_value,
             int max_value) const;
  double GetDouble(const std::string& flag, double fallback) const;
  struct Assignment {
    std::string option;  // OptionSet name, e.g. "run.threads"
    std::string value;
    std::string flag;  // as typed, e.g. "--threads"
  };
  const std::vector<Assignment>& core_assignments() const { return core_; }
  // Sets every core assignment in `set`, in command-line order; bad values
  // become UsageError naming the flag.
  void ApplyCoreAssignments(OptionSet* set) const;

 private:
  bool help_ = false;
  std::vector<std::string> positionals_;
  std::map<std::string, std::string> values_;
  std::vector<Assignment> core_;
};

// Prints "usage: wild_mvs NAME USAGE", the summary, the flags and, with
// `core`, the core options.
void PrintCommandHelp(const CommandSpec& spec, const OptionSet* core,
                      std::ostream& os);

// Splits "a,b,c" (empty items dropped).
std::vector<std::string> SplitList(const std::string& text, char sep = ',');

}  // namespace cli
}  // namespace wild_mvs
