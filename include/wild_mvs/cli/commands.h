// Copyright wild_mvs authors. The subcommands of the `wild_mvs` tool.
//
// Each takes the arguments after its name, writes results and progress,
// returns the exit status, and throws wild_mvs::Error (UsageError for
// command-line mistakes); main() turns those into
// "wild_mvs <command>: <message>" and a non-zero exit.
#pragma once

#include <string>
#include <vector>

namespace wild_mvs {
namespace cli {

using CommandArgs = std::vector<std::string>;

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const CommandArgs& args);
};

// All subcommands in the order `wild_mvs --help` lists them.
const std::vector<Command>& AllCommands();

int RunInfo(const CommandArgs& args);
int RunSparse(const CommandArgs& args);
int RunReconstruct(const CommandArgs& args);
int RunPhotos(const CommandArgs& args);
int RunFuse(const CommandArgs& args);
int RunMesh(const CommandArgs& args);
int RunEval(const CommandArgs& args);
int RunRender(const CommandArgs& args);
int RunToBag(const CommandArgs& args);

// Folder of the running executable (for sibling tools such as
// wild_mvs_to_bag), or "" when unknown.
std::string ExecutableDir();

}  // namespace cli
}  // namespace wild_mvs
