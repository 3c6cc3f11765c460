// Copyright wild_mvs authors. Inputs that the fuzz harnesses (test/fuzz/)
// found to crash, hang or misbehave, fed again to the fixed code. Each input
// is also kept in the harness's seed corpus (test/fuzz/corpus/<harness>/).
// In the sanitizer build (scripts/run_sanitizers.sh) these tests catch the
// memory errors themselves; in the normal build they check the results.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "test_paths.h"
#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

std::string ReadCorpus(const std::string& harness, const std::string& name) {
  const std::string path =
      testing::SourceDir() + "/test/fuzz/corpus/" + harness + "/" + name;
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// fuzz_yaml_config, first run: OptionSet::LoadYamlString kept references to
// the key / value nodes of a yaml-cpp iterator proxy that dies at the end of
// the statement (AddressSanitizer: stack-use-after-scope in
// YAML::Node::Mark()) on every config file. Fixed by copying the nodes.
TEST(FuzzRegressions, YamlConfigKeysOutliveTheIterator) {
  cli::ReconstructConfig config;
  cli::OptionSet options;
  cli::RegisterOptions(&config, &options);
  options.LoadYamlString(ReadCorpus("yaml_config", "small"), "small.yaml");
  EXPECT_EQ(config.run.threads, 2);
  EXPECT_EQ(config.image.max_image_size, 640);
  EXPECT_DOUBLE_EQ(config.image.cache_mb, 256.5);
  // The default config (the tool's own --dump-config) loads too.
  cli::ReconstructConfig defaults;
  cli::OptionSet options2;
  cli::RegisterOptions(&defaults, &options2);
  options2.LoadYamlString(ReadCorpus("yaml_config", "reconstruct_default"),
                          "reconstruct.yaml");
  EXPECT_TRUE(defaults.image.linearize);
  // Errors still name the line of the bad key.
  try {
    options.LoadYamlString("run:\n  threads: 1\n  bogus: 2\n", "bad.yaml");
    ADD_FAILURE() << "unknown key accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml line 3"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace wild_mvs
