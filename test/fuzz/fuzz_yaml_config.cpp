// Copyright wild_mvs authors. libFuzzer harness: the YAML config loader of
// `wild_mvs reconstruct --config FILE` (the same OptionSet / RegisterOptions
// the tool uses).
//
// Loading must either set the options or throw wild_mvs::Error; a config
// that loads and passes Check() must survive ToYaml -> load again with the
// same values.
#include <cstdint>
#include <cstdio>
#include <string>

#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  const std::string text(reinterpret_cast<const char*>(data), size);
  cli::ReconstructConfig config;
  cli::OptionSet options;
  cli::RegisterOptions(&config, &options);
  try {
    options.LoadYamlString(text, "fuzz.yaml");
    config.Check();
  } catch (const Error&) {
    return 0;
  }
  const std::string yaml = options.ToYaml(true);
  cli::ReconstructConfig again;
  cli::OptionSet options2;
  cli::RegisterOptions(&again, &options2);
  try {
    options2.LoadYamlString(yaml, "round trip");
    again.Check();
  } catch (const Error& e) {
    std::fprintf(stderr, "round trip failed: %s\n", e.what());
    __builtin_trap();  // the tool's own output must load
  }
  if (options2.ToYaml(false) != options.ToYaml(false)) __builtin_trap();
  return 0;
}
