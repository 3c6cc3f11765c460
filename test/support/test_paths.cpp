// Copyright wild_mvs authors.
#include "test_paths.h"

#include <cstdlib>
#include <filesystem>
#include <random>

namespace wild_mvs {
namespace testing {

namespace fs = std::filesystem;

bool PathExists(const std::string& path) { return fs::exists(path); }

std::string SharedDir() {
#ifdef WILD_MVS_SHARED_DIR
  if (fs::is_directory(WILD_MVS_SHARED_DIR)) return WILD_MVS_SHARED_DIR;
#endif
  if (const char* env = std::getenv("WILD_MVS_SHARED_DIR"))
    if (fs::is_directory(env)) return env;
  return "";
}

std::string SourceDir() {
#ifdef WILD_MVS_SOURCE_DIR
  return WILD_MVS_SOURCE_DIR;
#else
  return ".";
#endif
}

std::string MakeTempDir(const std::string& prefix) {
  std::random_device rd;
  for (int i = 0; i < 100; ++i) {
    fs::path p = fs::temp_directory_path() /
                 (prefix + "_" + std::to_string(rd() % 100000000));
    if (fs::create_directory(p)) return p.string();
  }
  return (fs::temp_directory_path() / prefix).string();
}

}  // namespace testing
}  // namespace wild_mvs
