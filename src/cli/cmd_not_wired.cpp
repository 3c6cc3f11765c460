// Copyright wild_mvs authors. TEMPORARY: parses and documents the commands
// whose library APIs have not landed on main yet; each moves to its own
// cmd_*.cpp when wired.
#include <iostream>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/specs.h"

namespace wild_mvs {
namespace cli {
namespace {
int NotYet(const CommandSpec& spec, const CommandArgs& argv) {
  Args args(spec, argv);
  if (args.help()) {
    PrintCommandHelp(spec, nullptr, std::cout);
    return 0;
  }
  throw Error(Msg("this build does not implement '", spec.name, "' yet"));
}
}  // namespace
int RunEval(const CommandArgs& a) { return NotYet(EvalSpec(), a); }
}  // namespace cli
}  // namespace wild_mvs
