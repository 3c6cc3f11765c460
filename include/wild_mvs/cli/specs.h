// Copyright wild_mvs authors. Command-line specifications (usage, flags,
// help text) of the wild_mvs subcommands, shared by the commands and tests.
#pragma once

#include "wild_mvs/cli/args.h"

namespace wild_mvs {
namespace cli {

CommandSpec InfoSpec();
CommandSpec SparseSpec();
CommandSpec FuseSpec();
CommandSpec MeshSpec();
CommandSpec EvalSpec();
CommandSpec RenderSpec();

// The dataset flags shared by info, sparse and reconstruct.
std::vector<FlagSpec> DatasetFlags();

}  // namespace cli
}  // namespace wild_mvs
