// Copyright wild_mvs authors. The wild_mvs command-line tool (placeholder
// dispatcher; subcommands are added in src/cli/).
#include <iostream>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: wild_mvs <info|sparse|reconstruct|fuse|mesh|eval|to-bag> ...\n";
    return 2;
  }
  std::cerr << "wild_mvs: unknown command '" << argv[1] << "'\n";
  return 2;
}
