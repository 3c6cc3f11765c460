// Copyright wild_mvs authors. YAML config files of an OptionRegistry
// (core/option_registry.h): nested maps whose path is the dotted key, e.g.
//   mvs:
//     mpgc:
//       drop_ncc: 0.4
// sets mvs.mpgc.drop_ncc. The same text loads with rosparam into a node's
// private namespace (~mvs/mpgc/drop_ncc). config/*.yaml are written by
// OptionsToYaml (a test keeps them equal).
#pragma once

#include <string>

#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

// Reads a YAML file of nested maps (sections) whose leaves are scalars and
// sets every leaf. Errors name the file, the line and the key: syntax
// errors, unknown keys, duplicate keys, non-scalar values, values that are
// not of the option's type. Ranges are left to the structs' Check().
void LoadOptionsYamlFile(OptionRegistry* registry, const std::string& path);
// Same for YAML text; `source` names it in errors.
void LoadOptionsYamlString(OptionRegistry* registry, const std::string& text,
                           const std::string& source);

// The current values as a YAML document (sections as nested maps, in
// registration order). With `with_comments`, each key is preceded by
// "# help (valid range)". Strings are quoted, infinity is .inf.
std::string OptionsToYaml(const OptionRegistry& registry, bool with_comments);

}  // namespace wild_mvs
