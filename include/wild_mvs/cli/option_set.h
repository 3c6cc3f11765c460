// Copyright wild_mvs authors. The command line's view of the option registry
// (core/option_registry.h): the option structs' fields, set from YAML config
// files (io/option_yaml.h) and --section.key flags.
//
// One registry serves the YAML config, the command-line flags, the help
// text and the ROS parameters, so they can never disagree: a key
// `mvs.mpgc.drop_ncc` is written
//   mvs:
//     mpgc:
//       drop_ncc: 0.4
// in a config file and `--mvs.mpgc.drop_ncc 0.4` on the command line. Values
// are parsed strictly by type (the whole text must be a number, finite).
// Unknown keys are errors naming the file and the line. After all values are
// set the caller runs the option structs' Check(), the only validator.
#pragma once

#include <ostream>
#include <string>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {
namespace cli {

class OptionSet : public OptionRegistry {
 public:
  // Reads a YAML config file / text (LoadOptionsYamlFile / String).
  void LoadYamlFile(const std::string& path);
  void LoadYamlString(const std::string& text, const std::string& source);

  // The current values as a YAML document, with each option's help and
  // valid range as a comment when `with_comments`.
  std::string ToYaml(bool with_comments) const;
  // "  --section.key TYPE  help (range; default VALUE)" lines.
  void PrintHelp(std::ostream& os) const;
};

}  // namespace cli
}  // namespace wild_mvs
