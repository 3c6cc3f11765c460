// Copyright wild_mvs authors. Where tests find data.
#pragma once

#include <string>

namespace wild_mvs {
namespace testing {

// ../shared beside the checkout, or "" when it does not exist (a user's
// clone): tests that need it call GTEST_SKIP() then.
std::string SharedDir();
// The source tree (for data shipped in the repo, e.g. data/).
std::string SourceDir();
// A fresh empty temporary directory, removed by the caller if wanted.
std::string MakeTempDir(const std::string& prefix);

}  // namespace testing
}  // namespace wild_mvs

// Skips the test unless ../shared/<rel> exists; sets `var` to its path.
#define WILD_MVS_REQUIRE_SHARED(var, rel)                                 \
  std::string var = ::wild_mvs::testing::SharedDir();                     \
  if (var.empty() || !::wild_mvs::testing::PathExists(var + "/" + rel)) { \
    GTEST_SKIP() << "../shared/" << rel << " not available";              \
  }                                                                       \
  var += "/" rel

namespace wild_mvs {
namespace testing {
bool PathExists(const std::string& path);
}  // namespace testing
}  // namespace wild_mvs
