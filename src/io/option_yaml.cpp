// Copyright wild_mvs authors.
#include "wild_mvs/io/option_yaml.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <vector>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

std::string Location(const std::string& source, const YAML::Mark& mark) {
  if (mark.is_null()) return source;
  return Msg(source, " line ", mark.line + 1);
}

std::string Quote(const std::string& v) {
  std::string q = "\"";
  for (char c : v) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

}  // namespace

void LoadOptionsYamlFile(OptionRegistry* registry, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Require(in.good(), path, ": cannot open config file");
  std::stringstream ss;
  ss << in.rdbuf();
  Require(!in.bad(), path, ": cannot read config file");
  LoadOptionsYamlString(registry, ss.str(), path);
}

void LoadOptionsYamlString(OptionRegistry* registry, const std::string& text,
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
          if (!registry->Has(name)) {
            // Is it a section name written as a leaf, or a typo?
            Require(!registry->IsSection(name), where, ": '", name,
                    "' is a section; its value must be a map of keys");
            registry->Set(name, "", where);  // throws "unknown option"
          }
          // `key:` (null) unsets an optional option.
          const bool unset = value.IsNull() && registry->Find(name)->optional();
          Require(value.IsScalar() || unset, where, ": value of '", name,
                  "' must be a single value, not a list or empty");
          registry->Set(name, unset ? std::string() : value.Scalar(), where);
        }
      };
  visit(root, "");
}

std::string OptionsToYaml(const OptionRegistry& registry, bool with_comments) {
  // Group by section path, keeping registration order.
  std::ostringstream os;
  std::vector<std::string> open;  // currently open section path
  bool first = true;
  for (const OptionRegistry::Option& e : registry.options()) {
    std::vector<std::string> parts;
    std::stringstream ss(e.key());
    for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
    const std::string leaf = parts.back();
    parts.pop_back();
    size_t common = 0;
    while (common < open.size() && common < parts.size() &&
           open[common] == parts[common]) {
      ++common;
    }
    // A blank line before a new top-level section (and after one).
    if (!first &&
        ((common == 0 && !parts.empty()) || (parts.empty() && !open.empty()))) {
      os << "\n";
    }
    open.resize(common);
    for (size_t i = common; i < parts.size(); ++i) {
      os << std::string(2 * i, ' ') << parts[i] << ":\n";
      open.push_back(parts[i]);
    }
    const std::string indent(2 * parts.size(), ' ');
    if (with_comments) {
      os << indent << "# " << e.help();
      const std::string range = e.RangeText();
      if (!range.empty()) os << " (" << range << ")";
      os << "\n";
    }
    std::string v = e.Text();
    if (e.type() == OptionRegistry::Type::kString) v = Quote(v);
    os << indent << leaf << ": " << v << "\n";
    first = false;
  }
  return os.str();
}

}  // namespace wild_mvs
