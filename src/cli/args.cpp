// Copyright wild_mvs authors.
#include "wild_mvs/cli/args.h"

#include <sstream>

namespace wild_mvs {
namespace cli {

Args::Args(const CommandSpec& spec, const std::vector<std::string>& argv,
           const OptionSet* core) {
  bool flags_done = false;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (flags_done || a.size() < 2 || a[0] != '-' ||
        (a[1] != '-' && a != "-h")) {
      positionals_.push_back(a);
      continue;
    }
    if (a == "--") {
      flags_done = true;
      continue;
    }
    if (a == "-h" || a == "--help") {
      help_ = true;
      continue;
    }
    std::string name = a.substr(2);
    std::string value;
    bool has_inline = false;
    const size_t eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_inline = true;
    }
    const FlagSpec* flag = nullptr;
    for (const FlagSpec& f : spec.flags) {
      if (f.name == name) flag = &f;
    }
    // Core options are written with underscores; accept dashes too.
    std::string core_name = name;
    for (char& c : core_name) {
      if (c == '-') c = '_';
    }
    const bool is_core = !flag && core && core->Has(core_name);
    if (!flag && !is_core) {
      throw UsageError(Msg("unknown option --", name, " (see wild_mvs ",
                           spec.name, " --help)"));
    }
    const bool is_alias = flag && !flag->alias_of.empty();
    const bool takes_value = is_core || !flag->metavar.empty();
    if (!takes_value) {
      if (has_inline) {
        ParseBool(value, "option --" + name);  // validates
      } else {
        value = "true";
      }
    } else if (!has_inline) {
      if (i + 1 >= argv.size()) {
        throw UsageError(Msg("option --", name, " needs a value",
                             flag ? " (" + flag->metavar + ")" : ""));
      }
      value = argv[++i];
    }
    if (is_core) {
      core_.push_back({core_name, value, "--" + name});
    } else if (is_alias) {
      core_.push_back({flag->alias_of, value, "--" + name});
    } else {
      values_[name] = value;
    }
  }
  if (help_) return;
  const int n = static_cast<int>(positionals_.size());
  if (n < spec.min_positionals) {
    std::string missing;
    for (int k = n; k < spec.min_positionals &&
                    k < static_cast<int>(spec.positionals.size());
         ++k) {
      missing += (missing.empty() ? "" : " ") + spec.positionals[k];
    }
    throw UsageError(Msg("missing argument ", missing, " (usage: wild_mvs ",
                         spec.name, " ", spec.usage, ")"));
  }
  if (n > spec.max_positionals) {
    throw UsageError(
        Msg("unexpected argument '", positionals_[spec.max_positionals],
            "' (usage: wild_mvs ", spec.name, " ", spec.usage, ")"));
  }
}

std::string Args::Get(const std::string& flag,
                      const std::string& fallback) const {
  auto it = values_.find(flag);
  return it == values_.end() ? fallback : it->second;
}

int Args::GetInt(const std::string& flag, int fallback, int min_value,
                 int max_value) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return fallback;
  int v = 0;
  try {
    v = ParseInt(it->second, "option --" + flag);
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  if (v < min_value || v > max_value) {
    throw UsageError(Msg("option --", flag, ": ", v, " is out of range [",
                         min_value, ", ", max_value, "]"));
  }
  return v;
}

double Args::GetDouble(const std::string& flag, double fallback) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return fallback;
  try {
    return ParseDouble(it->second, "option --" + flag);
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
}

void Args::ApplyCoreAssignments(OptionSet* set) const {
  for (const Assignment& a : core_) {
    try {
      set->Set(a.option, a.value, "option " + a.flag);
    } catch (const Error& e) {
      throw UsageError(e.what());
    }
  }
}

void PrintCommandHelp(const CommandSpec& spec, const OptionSet* core,
                      std::ostream& os) {
  os << "usage: wild_mvs " << spec.name << " " << spec.usage << "\n\n"
     << spec.summary << "\n";
  if (!spec.flags.empty()) {
    os << "\noptions:\n";
    for (const FlagSpec& f : spec.flags) {
      std::string left = "  --" + f.name;
      if (!f.metavar.empty()) left += " " + f.metavar;
      os << left;
      if (left.size() < 28) {
        os << std::string(28 - left.size(), ' ');
      } else {
        os << "\n" << std::string(28, ' ');
      }
      os << f.help << "\n";
    }
    os << "  -h, --help                print this help\n";
  }
  if (core && !core->options().empty()) {
    os << "\nalgorithm options (also settable in the --config YAML file under "
          "the same section and key):\n";
    core->PrintHelp(os);
  }
  if (!spec.epilog.empty()) os << "\n" << spec.epilog << "\n";
}

std::vector<std::string> SplitList(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, sep);) {
    const size_t b = item.find_first_not_of(" \t");
    if (b == std::string::npos) continue;
    const size_t e = item.find_last_not_of(" \t");
    out.push_back(item.substr(b, e - b + 1));
  }
  return out;
}

}  // namespace cli
}  // namespace wild_mvs
