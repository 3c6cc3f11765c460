// Copyright wild_mvs authors. Named options bound to the fields of the core's
// option structs, set from YAML config files and --section.key flags.
//
// One table serves the YAML config, the command-line flags and the help text,
// so the two can never disagree: a key `mvs.ncc_threshold` is written
//   mvs:
//     ncc_threshold: 0.3
// in a config file and `--mvs.ncc_threshold 0.3` on the command line. Values
// are parsed strictly (the whole text must be a number, finite, inside the
// registered range). Unknown keys are errors naming the file and the line.
// After all values are set the caller runs the option structs' Check().
#pragma once

#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace cli {

class OptionSet {
 public:
  struct Entry {
    std::string name;   // "section.key"
    std::string type;   // "bool", "int", "float", "string" or "a|b|c"
    std::string help;   // one line; says the default's meaning and the unit
    std::string range;  // human-readable range, e.g. "[0, 1]", or ""
    // Parses `text` and stores it; throws Error without location (the
    // caller prefixes the file/line or the flag).
    std::function<void(const std::string& text)> set;
    std::function<std::string()> get;  // current value as text
  };

  void Add(const std::string& name, bool* field, const std::string& help);
  void Add(const std::string& name, int* field, const std::string& help,
           int min_value, int max_value);
  // allow_infinite: "inf" / "-inf" are valid values (e.g. an open bounding
  // box); NaN never is.
  void Add(const std::string& name, double* field, const std::string& help,
           double min_value, double max_value, bool allow_infinite = false);
  void Add(const std::string& name, float* field, const std::string& help,
           double min_value, double max_value);
  void Add(const std::string& name, std::string* field,
           const std::string& help);
  // An enumeration shown and parsed by name.
  template <typename E>
  void AddEnum(const std::string& name, E* field, const std::string& help,
               const std::vector<std::pair<std::string, E>>& choices);

  bool Has(const std::string& name) const;
  const std::vector<Entry>& entries() const { return entries_; }

  // Sets one option from text; `where` prefixes errors (e.g. "option
  // --mvs.ncc_threshold" or "cfg.yaml line 3"). Throws Error for an unknown
  // name or a bad value.
  void Set(const std::string& name, const std::string& value,
           const std::string& where);
  // Reads a YAML file of nested maps (sections) whose leaves are scalars and
  // sets every leaf. Errors name the file, the line and the key: syntax
  // errors, unknown keys, duplicate keys, non-scalar values, bad values.
  void LoadYamlFile(const std::string& path);
  // Same for YAML text; `source` names it in errors.
  void LoadYamlString(const std::string& text, const std::string& source);

  // The current values as a YAML document (sections as nested maps), with
  // each option's help as a comment when `with_comments`.
  std::string ToYaml(bool with_comments) const;
  // "  --section.key TYPE  help (range; default VALUE)" lines.
  void PrintHelp(std::ostream& os) const;

 private:
  void AddEntry(Entry e);
  std::vector<Entry> entries_;
  std::map<std::string, size_t> index_;
};

// Strict scalar parsing shared with the argument parser; throw Error naming
// `what` when `text` is not a complete, finite value of the type.
int ParseInt(const std::string& text, const std::string& what);
double ParseDouble(const std::string& text, const std::string& what);
bool ParseBool(const std::string& text, const std::string& what);

template <typename E>
void OptionSet::AddEnum(const std::string& name, E* field,
                        const std::string& help,
                        const std::vector<std::pair<std::string, E>>& choices) {
  Entry e;
  e.name = name;
  e.help = help;
  for (size_t i = 0; i < choices.size(); ++i) {
    e.type += (i ? "|" : "") + choices[i].first;
  }
  const std::string type = e.type;
  e.set = [field, choices, type](const std::string& text) {
    for (const auto& c : choices) {
      if (c.first == text) {
        *field = c.second;
        return;
      }
    }
    throw Error(Msg("'", text, "' is not one of ", type));
  };
  e.get = [field, choices]() -> std::string {
    for (const auto& c : choices) {
      if (c.second == *field) return c.first;
    }
    return "?";
  };
  AddEntry(std::move(e));
}

}  // namespace cli
}  // namespace wild_mvs
