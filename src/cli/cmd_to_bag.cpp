// Copyright wild_mvs authors. `wild_mvs to-bag`: runs the ROS helper tool
// wild_mvs_to_bag (built only with WILD_MVS_WITH_ROS) with the same
// arguments.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/commands.h"

namespace wild_mvs {
namespace cli {
namespace {

bool IsExecutable(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
         access(path.c_str(), X_OK) == 0;
}

// wild_mvs_to_bag beside this binary, or in the catkin devel space of the
// same build (build/bin/wild_mvs and devel/bin/wild_mvs link to
// devel/lib/wild_mvs/wild_mvs, beside wild_mvs_to_bag).
std::string FindToBag() {
  const std::string dir = ExecutableDir();
  if (dir.empty()) return "";
  for (const std::string& candidate :
       {dir + "/wild_mvs_to_bag",
        dir + "/../devel/lib/wild_mvs/wild_mvs_to_bag",
        dir + "/../lib/wild_mvs/wild_mvs_to_bag"}) {
    if (IsExecutable(candidate)) return candidate;
  }
  return "";
}

}  // namespace

int RunToBag(const CommandArgs& args) {
  const std::string tool = FindToBag();
  if (tool.empty()) {
    bool help = false;
    for (const std::string& a : args) help |= (a == "--help" || a == "-h");
    const char* text =
        "usage: wild_mvs to-bag DATASET OUT.bag [options]\n\n"
        "Writes a dataset as a ROS 1 bag (images, camera info, tf) for the "
        "ROS\nnodes. This runs the wild_mvs_to_bag tool of the ROS build; "
        "this\nwild_mvs was built without ROS (WILD_MVS_WITH_ROS=OFF) or the "
        "tool\nwas not found beside it.";
    if (help) {
      std::cout << text << "\n";
      return 0;
    }
    throw Error(
        "built without ROS: the wild_mvs_to_bag tool was not found beside "
        "this executable (" +
        ExecutableDir() +
        "); build with -DWILD_MVS_WITH_ROS=ON (scripts/run_demo.sh does)");
  }
  std::vector<char*> argv;
  std::vector<std::string> storage = {tool};
  storage.insert(storage.end(), args.begin(), args.end());
  for (std::string& s : storage) argv.push_back(&s[0]);
  argv.push_back(nullptr);
  std::cout.flush();
  std::cerr.flush();
  execv(tool.c_str(), argv.data());
  throw Error(Msg("cannot run ", tool, ": ", std::strerror(errno)));
}

}  // namespace cli
}  // namespace wild_mvs
