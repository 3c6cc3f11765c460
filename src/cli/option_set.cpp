// Copyright wild_mvs authors.
#include "wild_mvs/cli/option_set.h"

#include "wild_mvs/io/option_yaml.h"

namespace wild_mvs {
namespace cli {

void OptionSet::LoadYamlFile(const std::string& path) {
  LoadOptionsYamlFile(this, path);
}

void OptionSet::LoadYamlString(const std::string& text,
                               const std::string& source) {
  LoadOptionsYamlString(this, text, source);
}

std::string OptionSet::ToYaml(bool with_comments) const {
  return OptionsToYaml(*this, with_comments);
}

void OptionSet::PrintHelp(std::ostream& os) const {
  for (const Option& e : options()) {
    const std::string type = e.type() == Type::kBool ? std::string("true|false")
                             : e.type() == Type::kString
                                 ? std::string("TEXT")
                                 : std::string(e.TypeName());
    const std::string flag = "  --" + e.key() + " " + type;
    os << flag;
    if (flag.size() < 44) {
      os << std::string(44 - flag.size(), ' ');
    } else {
      os << "\n" << std::string(44, ' ');
    }
    os << e.help() << " (";
    const std::string range = e.RangeText();
    if (!range.empty()) os << range << "; ";
    os << "default " << e.Text() << ")\n";
  }
}

}  // namespace cli
}  // namespace wild_mvs
