// Copyright wild_mvs authors. The prologue shared by the commands on the
// reconstruction options (reconstruct, sparse, fuse, mesh): the options of a
// ReconstructConfig registered, the command line parsed, --help printed, and
// the option layers applied in precedence order, then checked.
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/cli/run_steps.h"

namespace wild_mvs {
namespace cli {

class OptionCommand {
 public:
  // Registers *config's options and parses argv against spec (flags naming
  // a core option become core assignments). Throws UsageError. *config must
  // outlive this object.
  OptionCommand(const CommandSpec& spec, const CommandArgs& argv,
                ReconstructConfig* config);

  const CommandSpec& spec() const { return spec_; }
  const Args& args() const { return *args_; }
  // The options of the config (what --dump-config prints).
  const OptionSet& options() const { return options_; }

  // With --help: prints the command's help to os and returns true (the
  // command then returns 0).
  bool PrintHelpIfAsked(std::ostream& os) const;

  // Applies the option layers, later ones winning: the current values
  // (defaults, or a preset set by the caller) < --config FILE < the core
  // assignments of the command line; then checks the config.
  void Configure();

  // The same for a folder written by `wild_mvs reconstruct`: its run record
  // OUT/run.yaml (the options and *record, when the file exists) comes
  // before --config. Returns whether the run record exists.
  bool ConfigureWithRunRecord(const std::string& out, DatasetRecord* record);

 private:
  // --config FILE, then the core assignments, into `set`.
  void ApplyConfigFileAndFlags(OptionSet* set) const;

  CommandSpec spec_;
  ReconstructConfig* config_;
  OptionSet options_;
  std::optional<Args> args_;
};

}  // namespace cli
}  // namespace wild_mvs
