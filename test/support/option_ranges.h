// Copyright wild_mvs authors. Test helper: the valid range each registered
// option documents (OptionRegistry::Option::range(), written in the
// RegisterOptions functions and shown in config/*.yaml) agrees with what the
// options' Check() accepts, at the stated bounds.
//
// For every option of a root options struct (a fresh default one per probe):
//   - a value just outside a stated bound makes Check() throw;
//   - the bound itself (closed) or the value just inside it (open) passes,
//     unless the range has a note (a condition on other options);
//   - "odd": the even value next to the lower bound throws;
//   - "0 or ...": 0 passes and a value between 0 and the bound throws;
//   - choices: each passes, another string throws.
// And the defaults pass Check().
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {
namespace test {

template <typename Root>
using RegisterFn = std::function<void(Root*, OptionRegistry*)>;

// Whether Check() of a default Root accepts option `key` set by `set`.
template <typename Root>
bool CheckAccepts(const RegisterFn<Root>& reg, const std::string& key,
                  const std::function<void(OptionRegistry::Option*)>& set,
                  std::string* message) {
  Root root;
  OptionRegistry registry;
  reg(&root, &registry);
  set(registry.Find(key));
  try {
    root.Check();
  } catch (const Error& e) {
    *message = e.what();
    return false;
  }
  message->clear();
  return true;
}

template <typename Root>
void ExpectRangesAgreeWithCheck(const RegisterFn<Root>& reg) {
  Root defaults;
  OptionRegistry registry;
  reg(&defaults, &registry);
  ASSERT_NO_THROW(defaults.Check()) << "the defaults fail Check()";
  ASSERT_FALSE(registry.options().empty());
  int probes = 0;
  for (const OptionRegistry::Option& o : registry.options()) {
    const std::string& key = o.key();
    const OptionRegistry::Range& r = o.range();
    SCOPED_TRACE(key + " (" + o.RangeText() + ")");
    std::string msg;
    auto number = [&](double v) {
      return [&o, v](OptionRegistry::Option* x) {
        if (o.type() == OptionRegistry::Type::kInt) {
          x->SetInt(static_cast<long long>(v));
        } else {
          x->SetDouble(v);
        }
      };
    };
    auto expect = [&](double v, bool valid) {
      ++probes;
      const bool ok = CheckAccepts<Root>(reg, key, number(v), &msg);
      EXPECT_EQ(ok, valid) << key << " = " << v
                           << (valid ? " should pass" : " should fail")
                           << " Check(): " << msg;
    };
    const bool is_int = o.type() == OptionRegistry::Type::kInt;
    const double inf = std::numeric_limits<double>::infinity();
    if (o.type() == OptionRegistry::Type::kInt ||
        o.type() == OptionRegistry::Type::kDouble) {
      const bool inside_ok = r.note.empty();
      if (r.has_min) {
        const double out = r.min_open ? r.min
                           : is_int   ? r.min - 1
                                      : std::nextafter(r.min, -inf);
        if (!(r.or_zero && out == 0)) expect(out, false);
        const double in = !r.min_open ? r.min
                          : is_int    ? r.min + 1
                                      : std::nextafter(r.min, inf);
        if (inside_ok) expect(in, true);
        if (r.odd && r.min + 1 <= (r.has_max ? r.max : inf)) {
          expect(std::fmod(r.min, 2) == 0 ? r.min : r.min + 1, false);
        }
        if (r.or_zero) {
          expect(0, true);
          if (r.min > (is_int ? 1 : 0)) expect(is_int ? 1 : r.min / 2, false);
        }
      }
      if (r.has_max) {
        const double out = r.max_open ? r.max
                           : is_int   ? r.max + 1
                                      : std::nextafter(r.max, inf);
        expect(out, false);
        const double in = !r.max_open ? r.max
                          : is_int    ? r.max - 1
                                      : std::nextafter(r.max, -inf);
        if (inside_ok) expect(in, true);
      }
    }
    if (o.type() == OptionRegistry::Type::kString && !r.choices.empty()) {
      for (const std::string& c : r.choices) {
        ++probes;
        EXPECT_TRUE(CheckAccepts<Root>(
            reg, key, [&c](OptionRegistry::Option* x) { x->SetString(c); },
            &msg))
            << key << " = " << c << ": " << msg;
      }
      ++probes;
      EXPECT_FALSE(CheckAccepts<Root>(
          reg, key,
          [](OptionRegistry::Option* x) { x->SetString("not-a-choice"); },
          &msg))
          << key << " accepts any string";
    }
  }
  EXPECT_GT(probes, 0);
}

}  // namespace test
}  // namespace wild_mvs
