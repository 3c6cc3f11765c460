// Copyright wild_mvs authors.
#include "wild_mvs/core/option_registry.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string Prefix(const std::string& what) {
  return what.empty() ? std::string() : what + ": ";
}

// The shortest of 10..17 significant digits that reads back exactly (so a
// written config reloads to the same values).
std::string FormatDouble(double v) {
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  std::string text;
  for (int digits = 10; digits <= 17; ++digits) {
    std::ostringstream os;
    os << std::setprecision(digits) << v;
    text = os.str();
    if (std::strtod(text.c_str(), nullptr) == v) break;
  }
  return text;
}

const char* Expected(OptionRegistry::Type type) {
  switch (type) {
    case OptionRegistry::Type::kBool:
      return "a bool";
    case OptionRegistry::Type::kInt:
      return "an integer";
    case OptionRegistry::Type::kDouble:
      return "a number";
    default:
      return "a string";
  }
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

const char* OptionRegistry::Option::TypeName() const {
  switch (type_) {
    case Type::kBool:
      return "bool";
    case Type::kInt:
      return "int";
    case Type::kDouble:
      return "float";
    default:
      return "string";
  }
}

std::string OptionRegistry::Option::RangeText() const {
  const Range& r = range_;
  std::string out;
  auto add = [&out](const std::string& s) {
    out += (out.empty() ? "" : ", ") + s;
  };
  if (r.odd) add("odd");
  std::string bounds;
  if (r.has_min && r.has_max) {
    bounds = Msg(r.min_open ? "(" : "[", FormatDouble(r.min), ", ",
                 FormatDouble(r.max), r.max_open ? ")" : "]");
  } else if (r.has_min) {
    bounds = Msg(r.min_open ? "> " : ">= ", FormatDouble(r.min));
  } else if (r.has_max) {
    bounds = Msg(r.max_open ? "< " : "<= ", FormatDouble(r.max));
  }
  if (!bounds.empty()) add(r.or_zero ? "0 or " + bounds : bounds);
  if (!r.choices.empty()) {
    std::string c;
    for (const std::string& s : r.choices) c += (c.empty() ? "" : "|") + s;
    add(c);
  }
  if (!r.note.empty()) add(r.note);
  if (optional_) out = out.empty() ? "auto" : out + " or auto";
  return out;
}

OptionRegistry::Option& OptionRegistry::Option::Min(double v) {
  range_.has_min = true;
  range_.min = v;
  range_.min_open = false;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::Max(double v) {
  range_.has_max = true;
  range_.max = v;
  range_.max_open = false;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::Above(double v) {
  Min(v);
  range_.min_open = true;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::Below(double v) {
  Max(v);
  range_.max_open = true;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::Odd() {
  range_.odd = true;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::OrZero() {
  range_.or_zero = true;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::OneOf(
    const std::vector<std::string>& choices) {
  range_.choices = choices;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::Note(const std::string& text) {
  range_.note = text;
  return *this;
}
OptionRegistry::Option& OptionRegistry::Option::Infinite() {
  allow_infinite_ = true;
  return *this;
}

void OptionRegistry::Option::SetBool(bool v) {
  Require(type_ == Type::kBool, v ? "true" : "false", " is a bool, expected ",
          Expected(type_));
  *static_cast<bool*>(field_) = v;
}

void OptionRegistry::Option::SetInt(long long v) {
  if (type_ == Type::kDouble) {
    StoreDouble(static_cast<double>(v));
    return;
  }
  Require(type_ == Type::kInt, v, " is an integer, expected ", Expected(type_));
  Require(v >= std::numeric_limits<int>::min() &&
              v <= std::numeric_limits<int>::max(),
          v, " is too large");
  *static_cast<int*>(field_) = static_cast<int>(v);
}

void OptionRegistry::Option::SetDouble(double v) {
  if (type_ == Type::kInt) {
    Require(std::isfinite(v) && v == std::round(v) && std::abs(v) < 2e9,
            FormatDouble(v), " is a number, expected an integer");
    *static_cast<int*>(field_) = static_cast<int>(v);
    return;
  }
  Require(type_ == Type::kDouble, FormatDouble(v), " is a number, expected ",
          Expected(type_));
  Require(!std::isnan(v) && (allow_infinite_ || std::isfinite(v)), v,
          " is not a finite number");
  StoreDouble(v);
}

void OptionRegistry::Option::StoreDouble(double v) {
  if (optional_) {
    *static_cast<std::optional<double>*>(field_) = v;
  } else {
    *static_cast<double*>(field_) = v;
  }
}

bool OptionRegistry::Option::IsSet() const {
  return !optional_ ||
         static_cast<const std::optional<double>*>(field_)->has_value();
}

void OptionRegistry::Option::SetString(const std::string& v) {
  if (optional_) {  // "auto" / "" (other text: not a number)
    SetText(v);
    return;
  }
  Require(type_ == Type::kString, "'", v, "' is a string, expected ",
          Expected(type_));
  *static_cast<std::string*>(field_) = v;
}

void OptionRegistry::Option::SetText(const std::string& text) {
  switch (type_) {
    case Type::kBool:
      *static_cast<bool*>(field_) = ParseBool(text, "");
      return;
    case Type::kInt:
      *static_cast<int*>(field_) = ParseInt(text, "");
      return;
    case Type::kDouble: {
      const std::string s = Trim(text);
      const double inf = std::numeric_limits<double>::infinity();
      if (optional_ && (s.empty() || s == "auto")) {
        static_cast<std::optional<double>*>(field_)->reset();
      } else if (allow_infinite_ &&
                 (s == "inf" || s == ".inf" || s == "+inf" || s == "+.inf" ||
                  s == ".Inf" || s == ".INF")) {
        StoreDouble(inf);
      } else if (allow_infinite_ && (s == "-inf" || s == "-.inf" ||
                                     s == "-.Inf" || s == "-.INF")) {
        StoreDouble(-inf);
      } else {
        StoreDouble(ParseDouble(text, ""));
      }
      return;
    }
    case Type::kString:
      *static_cast<std::string*>(field_) = text;
      return;
  }
}

std::string OptionRegistry::Option::Text() const {
  switch (type_) {
    case Type::kBool:
      return GetBool() ? "true" : "false";
    case Type::kInt:
      return std::to_string(GetInt());
    case Type::kDouble:
      return IsSet() ? FormatDouble(GetDouble()) : "auto";
    default:
      return GetString();
  }
}

bool OptionRegistry::Option::GetBool() const {
  Require(type_ == Type::kBool, key_, " is not a bool");
  return *static_cast<const bool*>(field_);
}
int OptionRegistry::Option::GetInt() const {
  Require(type_ == Type::kInt, key_, " is not an int");
  return *static_cast<const int*>(field_);
}
double OptionRegistry::Option::GetDouble() const {
  Require(type_ == Type::kDouble, key_, " is not a float");
  Require(IsSet(), key_, " is unset (auto)");
  return optional_ ? **static_cast<const std::optional<double>*>(field_)
                   : *static_cast<const double*>(field_);
}
std::string OptionRegistry::Option::GetString() const {
  Require(type_ == Type::kString, key_, " is not a string");
  return *static_cast<const std::string*>(field_);
}

OptionRegistry::Option& OptionRegistry::AddOption(const std::string& key,
                                                  Type type, void* field,
                                                  const std::string& help) {
  Require(!key.empty() && !index_.count(key), "OptionRegistry: option '", key,
          "' registered twice");
  Option o;
  o.key_ = key;
  o.type_ = type;
  o.help_ = help;
  o.field_ = field;
  index_[key] = options_.size();
  options_.push_back(std::move(o));
  return options_.back();
}

OptionRegistry::Option& OptionRegistry::Add(const std::string& key, bool* field,
                                            const std::string& help) {
  return AddOption(key, Type::kBool, field, help);
}
OptionRegistry::Option& OptionRegistry::Add(const std::string& key, int* field,
                                            const std::string& help) {
  return AddOption(key, Type::kInt, field, help);
}
OptionRegistry::Option& OptionRegistry::Add(const std::string& key,
                                            double* field,
                                            const std::string& help) {
  return AddOption(key, Type::kDouble, field, help);
}
OptionRegistry::Option& OptionRegistry::Add(const std::string& key,
                                            std::optional<double>* field,
                                            const std::string& help) {
  Option& o = AddOption(key, Type::kDouble, field, help);
  o.optional_ = true;
  return o;
}
OptionRegistry::Option& OptionRegistry::Add(const std::string& key,
                                            std::string* field,
                                            const std::string& help) {
  return AddOption(key, Type::kString, field, help);
}

OptionRegistry::Option& OptionRegistry::Add(const Option& option) {
  Require(!option.key_.empty() && !index_.count(option.key_),
          "OptionRegistry: option '", option.key_, "' registered twice");
  index_[option.key_] = options_.size();
  options_.push_back(option);
  return options_.back();
}

OptionRegistry::Option* OptionRegistry::Find(const std::string& key) {
  auto it = index_.find(key);
  return it == index_.end() ? nullptr : &options_[it->second];
}

const OptionRegistry::Option* OptionRegistry::Find(
    const std::string& key) const {
  auto it = index_.find(key);
  return it == index_.end() ? nullptr : &options_[it->second];
}

void OptionRegistry::Set(const std::string& key, const std::string& text,
                         const std::string& where) {
  Option* o = Find(key);
  if (!o) {
    // Suggest the keys of the same section to help with typos.
    const size_t dot = key.rfind('.');
    std::string known;
    if (dot != std::string::npos) {
      const std::string section = key.substr(0, dot + 1);
      for (const Option& e : options_) {
        if (e.key().compare(0, section.size(), section) == 0) {
          known += (known.empty() ? "" : ", ") + e.key();
        }
      }
    }
    throw Error(Msg(where, ": unknown option '", key, "'",
                    known.empty() ? std::string(" (see --help)")
                                  : " (known in this section: " + known + ")"));
  }
  try {
    o->SetText(text);
  } catch (const Error& e) {
    // "cfg.yaml line 3: mvs.x: ..." but "option --mvs.x: ..." (no repeat).
    const bool named = where.find(key) != std::string::npos;
    throw Error(Msg(where, ": ", named ? "" : key + ": ", e.what()));
  }
}

bool OptionRegistry::IsSection(const std::string& section) const {
  const std::string p = section + ".";
  for (const Option& e : options_) {
    if (e.key().compare(0, p.size(), p) == 0) return true;
  }
  return false;
}

std::string OptionRegistry::Join(const std::string& prefix,
                                 const std::string& name) {
  return prefix.empty() ? name : prefix + "." + name;
}

}  // namespace wild_mvs
