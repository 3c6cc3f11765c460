// Copyright wild_mvs authors. The wild_mvs command-line tool: dispatches to
// the subcommands (src/cli/cmd_*.cpp) and turns every error into a message
// "wild_mvs <command>: <problem>" and a non-zero exit. Never crashes on bad
// input.
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/commands.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/mpgc_kernels.h"
#include "wild_mvs/core/stats.h"

namespace {

void PrintUsage(std::ostream& os) {
  os << "usage: wild_mvs <command> [arguments] [options]\n\n"
        "Multi-view stereo for community photo collections (Goesele et al.,\n"
        "ICCV 2007): depth maps, fused point cloud and mesh from calibrated\n"
        "images.\n\ncommands:\n";
  for (const auto& c : wild_mvs::cli::AllCommands()) {
    std::string name = c.name;
    os << "  " << name
       << std::string(name.size() < 13 ? 13 - name.size() : 1, ' ') << c.summary
       << "\n";
  }
  os << "\nRun 'wild_mvs <command> --help' for the arguments of a command.\n"
        "Exit status: 0 success, 1 error (input, output, algorithm), 2 bad "
        "command line.\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a closed pipe gives a write error
  // Freed images and depth maps go back to the system instead of leaving
  // holes in the heap (the peak RSS of long runs, docs/SCALE.md).
  wild_mvs::UseFixedMmapThreshold();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    PrintUsage(std::cerr);
    return 2;
  }
  const std::string cmd = args[0];
  if (cmd == "-h" || cmd == "--help" || cmd == "help") {
    PrintUsage(std::cout);
    return 0;
  }
  if (cmd == "--version") {
    std::cout << "wild_mvs 0.1.0\n";
    return 0;
  }
  const wild_mvs::cli::Command* command = nullptr;
  for (const auto& c : wild_mvs::cli::AllCommands()) {
    if (cmd == c.name) command = &c;
  }
  if (!command) {
    std::cerr << "wild_mvs: unknown command '" << cmd
              << "' (run 'wild_mvs --help' for the list)\n";
    return 2;
  }
  args.erase(args.begin());
  const std::string prefix = std::string("wild_mvs ") + command->name + ": ";
  // Benchmarks: cap the SIMD kernels' instruction set (e.g. AVX2 on an
  // AVX-512 CPU, mpgc_kernels.h).
  if (const char* simd = std::getenv("WILD_MVS_SIMD_TARGET")) {
    if (*simd && !wild_mvs::mpgc_kernels::LimitTarget(simd)) {
      std::cerr << prefix << "WILD_MVS_SIMD_TARGET=" << simd
                << " is not an instruction set of this binary on this CPU"
                << " (e.g. AVX3, AVX2, SSE4)\n";
      return 2;
    }
  }
  try {
    return command->run(args);
  } catch (const wild_mvs::cli::UsageError& e) {
    std::cerr << prefix << e.what() << "\n";
    return 2;
  } catch (const wild_mvs::Error& e) {
    std::cerr << prefix << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << prefix
              << "out of memory (try --max-image-size or fewer --threads)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << prefix << "internal error: " << e.what() << "\n";
    return 1;
  } catch (...) {
    std::cerr << prefix << "internal error (unknown exception)\n";
    return 1;
  }
}
