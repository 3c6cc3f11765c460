// Copyright wild_mvs authors. One registry of the option structs' fields
// (ROS-free, no YAML): every options struct registers its fields with a key,
// a pointer, a help line and its valid range as Check() states it, with a
// RegisterOptions() overload declared beside the struct. The command line
// (--mvs.mpgc.drop_ncc), the YAML config files (mvs: mpgc: drop_ncc:) and
// the ROS parameter reader (~mvs/mpgc/drop_ncc) all walk the same registry,
// and config/*.yaml are generated from it.
//
// Keys are dotted paths: struct nesting gives the sections, e.g.
//   MvsOptions m;  RegisterOptions(&registry, "mvs", &m);
// registers "mvs.mpgc.drop_ncc" for m.mpgc.drop_ncc.
//
// The registry does not validate ranges: Check() of the options struct is the
// only validator and its message is what the user sees. The registry parses
// values strictly by type (a whole integer, a finite number, true/false) and
// documents the range (Option::RangeText()); a test checks that the stated
// bounds agree with Check().
//
// A std::optional<double> field is an option that may be unset (e.g. "auto":
// the code chooses): it is written `auto` when unset, and the text `auto` or
// an empty value (command line `--key auto`, YAML `key: auto` or `key:`, the
// ROS string parameter "auto") unsets it; a key that is not given keeps the
// default. Its range text ends in "or auto".
//
// The registry holds pointers into the registered structs: they must outlive
// it and must not move.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace wild_mvs {

class OptionRegistry {
 public:
  enum class Type { kBool, kInt, kDouble, kString };

  // The valid values of an option as its struct's Check() states them.
  struct Range {
    bool has_min = false, has_max = false;
    double min = 0, max = 0;
    bool min_open = false, max_open = false;  // "> min" / "< max"
    bool odd = false;                         // integers: odd values only
    bool or_zero = false;              // 0 is valid too ("0 (off) or >= 64")
    std::vector<std::string> choices;  // strings: the valid values
    // Further conditions Check() states (involving other options), e.g.
    // "> settle_iterations"; shown, not tested at the bound.
    std::string note;
  };

  class Option {
   public:
    const std::string& key() const { return key_; }
    Type type() const { return type_; }
    const std::string& help() const { return help_; }
    const Range& range() const { return range_; }
    bool allow_infinite() const { return allow_infinite_; }
    // A std::optional<double> field (type kDouble) that may be unset.
    bool optional() const { return optional_; }
    // False only for an unset optional option.
    bool IsSet() const;
    // "bool", "int", "float" or "string".
    const char* TypeName() const;
    // "odd, [3, 9]", ">= 0", "tf|topic", "> 0, > settle_iterations",
    // "> 0 or auto" (optional), or "".
    std::string RangeText() const;

    // Documentation of the range (builder style, in RegisterOptions):
    //   registry->Add(p + ".window", &o->window, "...").Min(3).Max(9).Odd();
    Option& Min(double v);    // >= v
    Option& Max(double v);    // <= v
    Option& Above(double v);  // > v
    Option& Below(double v);  // < v
    Option& Odd();
    Option& OrZero();
    Option& OneOf(const std::vector<std::string>& choices);
    Option& Note(const std::string& text);
    // Doubles: "inf" / "-inf" are values (e.g. an open bounding box).
    Option& Infinite();

    // Typed setters (ROS parameters). Throw Error (without the key) when the
    // type does not fit: an integer is accepted for a double, an integral
    // double for an integer; NaN (and infinity unless allow_infinite) never.
    void SetBool(bool v);
    void SetInt(long long v);
    void SetDouble(double v);
    void SetString(const std::string& v);
    // Parses text by type (command line, YAML scalars) and stores it; throws
    // Error (without the key) when it is not a value of the type. For an
    // optional option "auto" and "" unset it.
    void SetText(const std::string& text);
    // The current value as text (parsed back by SetText). Infinity is
    // written ".inf" / "-.inf" (YAML's spelling), an unset optional "auto".
    std::string Text() const;

    bool GetBool() const;
    int GetInt() const;
    // Throws Error for an unset optional option (see IsSet).
    double GetDouble() const;
    std::string GetString() const;

   private:
    friend class OptionRegistry;
    std::string key_;
    Type type_ = Type::kBool;
    std::string help_;
    Range range_;
    bool allow_infinite_ = false;
    bool optional_ = false;  // field_ is a std::optional<double>
    void* field_ = nullptr;
    void StoreDouble(double v);
  };

  // Registers a field. T is bool, int, double, std::optional<double> (type
  // kDouble, may be unset: see above) or std::string. Throws Error when the
  // key is registered twice.
  Option& Add(const std::string& key, bool* field, const std::string& help);
  Option& Add(const std::string& key, int* field, const std::string& help);
  Option& Add(const std::string& key, double* field, const std::string& help);
  Option& Add(const std::string& key, std::optional<double>* field,
              const std::string& help);
  Option& Add(const std::string& key, std::string* field,
              const std::string& help);
  // Registers a copy of an option of another registry (the same key, field,
  // help and range), to offer a subset of a struct's registered options.
  // Throws Error when the key is registered already.
  Option& Add(const Option& option);

  bool Has(const std::string& key) const { return index_.count(key) > 0; }
  // nullptr when the key is not registered.
  Option* Find(const std::string& key);
  const Option* Find(const std::string& key) const;
  // Sets option `key` from text (Option::SetText); `where` prefixes errors
  // (e.g. "option --mvs.mpgc.window" or "cfg.yaml line 3"). Throws Error for
  // an unknown key (listing the keys of its section) or a value that is not
  // of the option's type.
  void Set(const std::string& key, const std::string& text,
           const std::string& where);
  // True when some key starts with "section." (e.g. "mvs.mpgc").
  bool IsSection(const std::string& section) const;

  // In registration order.
  const std::deque<Option>& options() const { return options_; }
  std::deque<Option>& options() { return options_; }

  // "prefix.name", or "name" for an empty prefix.
  static std::string Join(const std::string& prefix, const std::string& name);

 private:
  Option& AddOption(const std::string& key, Type type, void* field,
                    const std::string& help);
  std::deque<Option> options_;
  std::map<std::string, size_t> index_;
};

// Strict scalar parsing shared by the registry and the command line; throw
// Error naming `what` (when not empty) when `text` is not a complete, finite
// value of the type.
int ParseInt(const std::string& text, const std::string& what);
double ParseDouble(const std::string& text, const std::string& what);
bool ParseBool(const std::string& text, const std::string& what);

}  // namespace wild_mvs
