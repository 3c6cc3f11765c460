// Copyright wild_mvs authors.
#include "wild_mvs/cli/option_set.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace cli {
namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string FormatDouble(double v) {
  std::ostringstream os;
  os << std::setprecision(10) << v;
  return os.str();
}

std::string RangeText(double lo, double hi) {
  const double inf = std::numeric_limits<double>::infinity();
  const bool int_lo = lo <= -std::numeric_limits<int>::max();
  const bool int_hi = hi >= std::numeric_limits<int>::max();
  if ((lo == -inf || int_lo) && (hi == inf || int_hi)) return "";
  if (lo == -inf || int_lo) return "<= " + FormatDouble(hi);
  if (hi == inf || int_hi) return ">= " + FormatDouble(lo);
  return "[" + FormatDouble(lo) + ", " + FormatDouble(hi) + "]";
}

void CheckRange(double v, double lo, double hi, const std::string& text) {
  Require(v >= lo && v <= hi, "value ", text, " is out of range ",
          RangeText(lo, hi));
}

std::string Location(const std::string& source, const YAML::Mark& mark) {
  if (mark.is_null()) return source;
  return Msg(source, " line ", mark.line + 1);
}

std::string Prefix(const std::string& what) {
  return what.empty() ? std::string() : what + ": ";
}

}  // namespace

int ParseInt(const std::string& text, const std::string& what) {
  const std::string t = Trim(text);
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(t.c_str(), &end, 10);
  Require(!t.empty() && end && *end == '\0', Prefix(what), "'", text,
          "' is not an integer");
  Require(errno != ERANGE && v >= std::numeric_limits<int>::min() &&
              v <= std::numeric_limits<int>::max(),
          Prefix(what), "'", text, "' is too large");
  return static_cast<int>(v);
}

double ParseDouble(const std::string& text, const std::string& what) {
  const std::string t = Trim(text);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  Require(!t.empty() && end && *end == '\0', Prefix(what), "'", text,
          "' is not a number");
  Require(std::isfinite(v), Prefix(what), "'", text,
          "' is not a finite number");
  return v;
}

bool ParseBool(const std::string& text, const std::string& what) {
  const std::string t = Trim(text);
  if (t == "true" || t == "1" || t == "yes" || t == "on") return true;
  if (t == "false" || t == "0" || t == "no" || t == "off") return false;
  throw Error(Msg(Prefix(what), "'", text, "' is not a boolean (true/false)"));
}

void OptionSet::AddEntry(Entry e) {
  Require(!e.name.empty() && !index_.count(e.name), "OptionSet: option '",
          e.name, "' registered twice");
  index_[e.name] = entries_.size();
  entries_.push_back(std::move(e));
}

void OptionSet::Add(const std::string& name, bool* field,
                    const std::string& help) {
  Entry e{name, "bool", help, "", nullptr, nullptr};
  e.set = [field](const std::string& t) { *field = ParseBool(t, ""); };
  e.get = [field] { return std::string(*field ? "true" : "false"); };
  AddEntry(std::move(e));
}

void OptionSet::Add(const std::string& name, int* field,
                    const std::string& help, int lo, int hi) {
  Entry e{name, "int", help, RangeText(lo, hi), nullptr, nullptr};
  e.set = [field, lo, hi](const std::string& t) {
    const int v = ParseInt(t, "");
    CheckRange(v, lo, hi, Trim(t));
    *field = v;
  };
  e.get = [field] { return std::to_string(*field); };
  AddEntry(std::move(e));
}

void OptionSet::Add(const std::string& name, double* field,
                    const std::string& help, double lo, double hi,
                    bool allow_infinite) {
  Entry e{name, "float", help, RangeText(lo, hi), nullptr, nullptr};
  e.set = [field, lo, hi, allow_infinite](const std::string& t) {
    const std::string s = Trim(t);
    const double inf = std::numeric_limits<double>::infinity();
    double v = 0;
    if (allow_infinite && (s == "inf" || s == ".inf" || s == "+inf")) {
      v = inf;
    } else if (allow_infinite && (s == "-inf" || s == "-.inf")) {
      v = -inf;
    } else {
      v = ParseDouble(t, "");
    }
    CheckRange(v, lo, hi, Trim(t));
    *field = v;
  };
  e.get = [field] { return FormatDouble(*field); };
  AddEntry(std::move(e));
}

void OptionSet::Add(const std::string& name, float* field,
                    const std::string& help, double lo, double hi) {
  Entry e{name, "float", help, RangeText(lo, hi), nullptr, nullptr};
  e.set = [field, lo, hi](const std::string& t) {
    const double v = ParseDouble(t, "");
    CheckRange(v, lo, hi, Trim(t));
    *field = static_cast<float>(v);
  };
  e.get = [field] { return FormatDouble(*field); };
  AddEntry(std::move(e));
}

void OptionSet::Add(const std::string& name, std::string* field,
                    const std::string& help) {
  Entry e{name, "string", help, "", nullptr, nullptr};
  e.set = [field](const std::string& t) { *field = t; };
  e.get = [field] { return *field; };
  AddEntry(std::move(e));
}

bool OptionSet::Has(const std::string& name) const {
  return index_.count(name) > 0;
}

void OptionSet::Set(const std::string& name, const std::string& value,
                    const std::string& where) {
  auto it = index_.find(name);
  if (it == index_.end()) {
    // Suggest the keys of the same section to help with typos.
    const size_t dot = name.rfind('.');
    std::string known;
    if (dot != std::string::npos) {
      const std::string section = name.substr(0, dot + 1);
      for (const Entry& e : entries_) {
        if (e.name.compare(0, section.size(), section) == 0) {
          known += (known.empty() ? "" : ", ") + e.name;
        }
      }
    }
    throw Error(Msg(where, ": unknown option '", name, "'",
                    known.empty() ? std::string(" (see --help)")
                                  : " (known in this section: " + known + ")"));
  }
  try {
    entries_[it->second].set(value);
  } catch (const Error& e) {
    // "cfg.yaml line 3: mvs.x: ..." but "option --mvs.x: ..." (no repeat).
    const bool named = where.find(name) != std::string::npos;
    throw Error(Msg(where, ": ", named ? "" : name + ": ", e.what()));
  }
}

void OptionSet::LoadYamlFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Require(in.good(), path, ": cannot open config file");
  std::stringstream ss;
  ss << in.rdbuf();
  Require(!in.bad(), path, ": cannot read config file");
  LoadYamlString(ss.str(), path);
}

void OptionSet::LoadYamlString(const std::string& text,
                               const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(Msg(Location(source, e.mark), ": YAML syntax error: ", e.msg));
  }
  if (root.IsNull()) return;  // empty file: defaults
  Require(root.IsMap(), Location(source, root.Mark()),
          ": the config must be a map of sections (e.g. 'mvs:' followed by "
          "indented 'key: value' lines)");
  // Depth-first over nested maps; leaves are scalars named by the joined
  // path of keys.
  std::function<void(const YAML::Node&, const std::string&)> visit =
      [&](const YAML::Node& map, const std::string& prefix) {
        std::set<std::string> seen;
        for (auto it = map.begin(); it != map.end(); ++it) {
          // Copies: `it->first` lives in a proxy that dies at the end of
          // the full expression (a reference dangles; found by fuzzing).
          const YAML::Node key = it->first;
          const YAML::Node value = it->second;
          const std::string where = Location(source, key.Mark());
          Require(key.IsScalar(), where, ": keys must be plain names");
          const std::string name = prefix + key.Scalar();
          Require(seen.insert(key.Scalar()).second, where, ": duplicate key '",
                  name, "'");
          if (value.IsMap()) {
            visit(value, name + ".");
            continue;
          }
          if (!Has(name)) {
            // Is it a section name written as a leaf, or a typo?
            bool is_section = false;
            for (const Entry& e : entries_) {
              if (e.name.compare(0, name.size() + 1, name + ".") == 0) {
                is_section = true;
              }
            }
            Require(!is_section, where, ": '", name,
                    "' is a section; its value must be a map of keys");
            Set(name, "", where);  // throws "unknown option" with hints
          }
          Require(value.IsScalar(), where, ": value of '", name,
                  "' must be a single value, not a list or empty");
          Set(name, value.Scalar(), where);
        }
      };
  visit(root, "");
}

std::string OptionSet::ToYaml(bool with_comments) const {
  // Group by section path, keeping registration order.
  std::ostringstream os;
  std::vector<std::string> open;  // currently open section path
  for (const Entry& e : entries_) {
    std::vector<std::string> parts;
    std::stringstream ss(e.name);
    for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
    const std::string leaf = parts.back();
    parts.pop_back();
    size_t common = 0;
    while (common < open.size() && common < parts.size() &&
           open[common] == parts[common]) {
      ++common;
    }
    open.resize(common);
    for (size_t i = common; i < parts.size(); ++i) {
      if (i == 0 && !os.str().empty()) os << "\n";
      os << std::string(2 * i, ' ') << parts[i] << ":\n";
      open.push_back(parts[i]);
    }
    const std::string indent(2 * parts.size(), ' ');
    if (with_comments) {
      os << indent << "# " << e.help;
      if (!e.range.empty()) os << " (" << e.range << ")";
      if (e.type.find('|') != std::string::npos) os << " (" << e.type << ")";
      os << "\n";
    }
    std::string v = e.get();
    if (e.type == "string") {
      // Quote strings so empty values and special characters survive.
      std::string q = "\"";
      for (char c : v) {
        if (c == '"' || c == '\\') q += '\\';
        q += c;
      }
      v = q + "\"";
    }
    os << indent << leaf << ": " << v << "\n";
  }
  return os.str();
}

void OptionSet::PrintHelp(std::ostream& os) const {
  for (const Entry& e : entries_) {
    std::string flag = "  --" + e.name + " " +
                       (e.type == "bool"     ? std::string("true|false")
                        : e.type == "string" ? "TEXT"
                                             : e.type);
    os << flag;
    if (flag.size() < 44) {
      os << std::string(44 - flag.size(), ' ');
    } else {
      os << "\n" << std::string(44, ' ');
    }
    os << e.help << " (";
    if (!e.range.empty()) os << e.range << "; ";
    os << "default " << e.get() << ")\n";
  }
}

}  // namespace cli
}  // namespace wild_mvs
