// Copyright wild_mvs authors. The option registry: keys, parsing, YAML round
// trip, and the documented ranges agree with Check().
#include <gtest/gtest.h>

#include <limits>
#include <optional>
#include <set>

#include "option_ranges.h"
#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/io/option_yaml.h"

namespace wild_mvs {
namespace {

TEST(OptionRegistry, StructNestingGivesTheKeys) {
  cli::ReconstructConfig c;
  OptionRegistry r;
  cli::RegisterOptions(&c, &r);
  for (const char* key :
       {"run.threads", "image.cache_mb", "tracker.features.max_image_size",
        "tracker.max_neighbors", "mvs.global.num_neighbors",
        "mvs.local.num_active", "mvs.mpgc.window", "mvs.mpgc.drop_ncc",
        "mvs.growing.revisit_margin", "mvs.sweep.below_seeds",
        "consistency.min_consistent", "ablation.color",
        "ablation.local_view_selection", "ablation.consistency",
        "fusion.bbox_min_x", "fusion.pending_mb", "meshing.depth"}) {
    EXPECT_TRUE(r.Has(key)) << key;
  }
  // Each key points at its field.
  r.Find("mvs.mpgc.drop_ncc")->SetText("0.55");
  EXPECT_DOUBLE_EQ(c.mvs.mpgc.drop_ncc, 0.55);
  r.Find("mvs.mpgc.window")->SetInt(7);
  EXPECT_EQ(c.mvs.mpgc.window, 7);
  r.Find("meshing.trim_distance")->SetInt(3);  // int for a double
  EXPECT_DOUBLE_EQ(c.mesh.trim_distance, 3.0);
  r.Find("ablation.local_view_selection")->SetBool(false);
  EXPECT_FALSE(c.mvs.ablation.local_view_selection);
  r.Find("ablation.linearize")->SetBool(false);
  EXPECT_FALSE(c.LoaderOptions().linearize);
  r.Find("run.stages")->SetString("depth");
  EXPECT_EQ(c.run.stages, "depth");
  // Every key is unique and every option has help.
  std::set<std::string> keys;
  for (const auto& o : r.options()) {
    EXPECT_TRUE(keys.insert(o.key()).second) << o.key();
    EXPECT_FALSE(o.help().empty()) << o.key();
  }
  EXPECT_THROW(r.Add("run.threads", &c.run.threads, "again"), Error);
  // The options a user of `reconstruct` may need, and no more (the
  // ablation switches included).
  EXPECT_LE(r.options().size(), 60u);
}

// A copy of another registry's option sets the same field and keeps its
// help and range (a node offers a subset of a struct's options).
TEST(OptionRegistry, AddCopiesAnOptionOfAnotherRegistry) {
  MvsOptions m;
  OptionRegistry all;
  RegisterOptions(&all, "mvs", &m);
  OptionRegistry some;
  const OptionRegistry::Option& w = some.Add(*all.Find("mvs.mpgc.window"));
  EXPECT_EQ(w.key(), "mvs.mpgc.window");
  EXPECT_EQ(w.help(), all.Find("mvs.mpgc.window")->help());
  EXPECT_EQ(w.RangeText(), all.Find("mvs.mpgc.window")->RangeText());
  ASSERT_EQ(some.options().size(), 1u);
  some.Find("mvs.mpgc.window")->SetInt(7);
  EXPECT_EQ(m.mpgc.window, 7);
  EXPECT_FALSE(some.Has("mvs.mpgc.drop_ncc"));
  EXPECT_THROW(some.Add(*all.Find("mvs.mpgc.window")), Error);
}

TEST(OptionRegistry, ParsesByTypeOnly) {
  int i = 0;
  double d = 0, box = 0;
  bool b = false;
  std::string s;
  OptionRegistry r;
  r.Add("a.i", &i, "int").Min(0);
  r.Add("a.d", &d, "double");
  r.Add("a.box", &box, "open bound").Infinite();
  r.Add("a.b", &b, "bool");
  r.Add("a.s", &s, "string");
  r.Set("a.i", "-5", "here");  // out of the stated range: Check()'s job
  EXPECT_EQ(i, -5);
  EXPECT_THROW(r.Set("a.i", "2.5", "here"), Error);
  EXPECT_THROW(r.Set("a.i", "99999999999", "here"), Error);
  EXPECT_THROW(r.Set("a.d", "nan", "here"), Error);
  EXPECT_THROW(r.Set("a.d", "inf", "here"), Error);
  r.Set("a.box", "-.inf", "here");
  EXPECT_EQ(box, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(r.Find("a.box")->Text(), "-.inf");
  EXPECT_THROW(r.Set("a.b", "maybe", "here"), Error);
  EXPECT_THROW(r.Find("a.b")->SetInt(1), Error);
  EXPECT_THROW(r.Find("a.i")->SetDouble(1.5), Error);
  EXPECT_THROW(r.Find("a.s")->SetDouble(1.5), Error);
  try {
    r.Set("a.x", "1", "option --a.x");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("known in this section: a.i"),
              std::string::npos)
        << e.what();
  }
}

TEST(OptionRegistry, OptionalDoubleMayBeUnset) {
  std::optional<double> depth;
  OptionRegistry r;
  OptionRegistry::Option& o =
      r.Add("a.depth", &depth, "scene depth; auto = estimated").Above(0);
  EXPECT_TRUE(o.optional());
  EXPECT_EQ(o.type(), OptionRegistry::Type::kDouble);
  EXPECT_EQ(o.RangeText(), "> 0 or auto");
  EXPECT_FALSE(o.IsSet());
  EXPECT_EQ(o.Text(), "auto");
  EXPECT_THROW(o.GetDouble(), Error);
  r.Set("a.depth", "2.5", "here");
  ASSERT_TRUE(depth.has_value());
  EXPECT_EQ(*depth, 2.5);
  EXPECT_TRUE(o.IsSet());
  EXPECT_EQ(o.GetDouble(), 2.5);
  EXPECT_EQ(o.Text(), "2.5");
  r.Set("a.depth", " auto ", "here");
  EXPECT_FALSE(depth.has_value());
  o.SetInt(3);  // a ROS integer parameter
  EXPECT_EQ(depth, std::optional<double>(3.0));
  o.SetText("");  // an empty value unsets
  EXPECT_FALSE(depth.has_value());
  o.SetDouble(0.25);
  EXPECT_EQ(depth, std::optional<double>(0.25));
  o.SetString("auto");  // a ROS string parameter
  EXPECT_FALSE(depth.has_value());
  // Anything else must be a finite number.
  EXPECT_THROW(r.Set("a.depth", "automatic", "here"), Error);
  EXPECT_THROW(r.Set("a.depth", "inf", "here"), Error);
  EXPECT_THROW(o.SetString("far"), Error);
  EXPECT_THROW(o.SetDouble(std::numeric_limits<double>::quiet_NaN()), Error);
  EXPECT_FALSE(depth.has_value());
}

TEST(OptionRegistry, OptionalDoubleInYaml) {
  std::optional<double> a = 1.5, b = 2.0, c;
  cli::OptionSet r;
  r.Add("s.a", &a, "a");
  r.Add("s.b", &b, "b");
  r.Add("s.c", &c, "c");
  // `auto` and an empty value unset; a key not given keeps its value.
  r.LoadYamlString("s:\n  a: auto\n  b:\n", "cfg.yaml");
  EXPECT_FALSE(a.has_value());
  EXPECT_FALSE(b.has_value());
  EXPECT_FALSE(c.has_value());
  r.LoadYamlString("s:\n  c: 4\n", "cfg.yaml");
  EXPECT_EQ(c, std::optional<double>(4.0));
  EXPECT_FALSE(a.has_value());
  // Written as `auto`, read back the same.
  const std::string yaml = r.ToYaml(false);
  EXPECT_EQ(yaml, "s:\n  a: auto\n  b: auto\n  c: 4\n");
  std::optional<double> a2 = 7, b2 = 7, c2;
  cli::OptionSet r2;
  r2.Add("s.a", &a2, "a");
  r2.Add("s.b", &b2, "b");
  r2.Add("s.c", &c2, "c");
  r2.LoadYamlString(yaml, "dump");
  EXPECT_FALSE(a2.has_value());
  EXPECT_FALSE(b2.has_value());
  EXPECT_EQ(c2, std::optional<double>(4.0));
  // An empty value is an error where the option may not be unset.
  double d = 1;
  r2.Add("s.d", &d, "d");
  EXPECT_THROW(r2.LoadYamlString("s:\n  d:\n", "cfg.yaml"), Error);
}

TEST(OptionRegistry, TrackerSceneDepthIsAutoByDefault) {
  cli::ReconstructConfig c;
  OptionRegistry r;
  cli::RegisterOptions(&c, &r);
  EXPECT_FALSE(c.tracker.scene_depth.has_value());
  EXPECT_EQ(r.Find("tracker.scene_depth")->Text(), "auto");
  r.Set("tracker.scene_depth", "3", "test");
  EXPECT_EQ(c.tracker.scene_depth, std::optional<double>(3.0));
  EXPECT_NO_THROW(c.tracker.Check());
  c.tracker.scene_depth = 0.0;  // set, but not a depth
  EXPECT_THROW(c.tracker.Check(), Error);
}

TEST(OptionRegistry, RangeText) {
  int w = 5, z = 0;
  double x = 0;
  OptionRegistry r;
  EXPECT_EQ(r.Add("w", &w, "").Min(3).Max(9).Odd().RangeText(), "odd, [3, 9]");
  EXPECT_EQ(r.Add("z", &z, "").Min(64).OrZero().RangeText(), "0 or >= 64");
  EXPECT_EQ(r.Add("x", &x, "").Above(0).Below(1).RangeText(), "(0, 1)");
}

TEST(OptionRegistry, ReconstructRangesAgreeWithCheck) {
  test::ExpectRangesAgreeWithCheck<cli::ReconstructConfig>(
      [](cli::ReconstructConfig* c, OptionRegistry* r) {
        cli::RegisterOptions(c, r);
      });
}

TEST(OptionRegistry, YamlRoundTrip) {
  cli::ReconstructConfig a;
  cli::OptionSet ra;
  cli::RegisterOptions(&a, &ra);
  ra.Set("mvs.mpgc.drop_ncc", "0.45", "test");
  ra.Set("fusion.bbox_max_z", "3.5", "test");
  ra.Set("run.stages", "depth,fuse", "test");
  const std::string yaml = ra.ToYaml(true);
  EXPECT_NE(yaml.find("    # matching window side n of n x n (paper: 5) "
                      "(odd, [3, 9])\n    window: 5\n"),
            std::string::npos)
      << yaml;
  cli::ReconstructConfig b;
  cli::OptionSet rb;
  cli::RegisterOptions(&b, &rb);
  rb.LoadYamlString(yaml, "dump");
  EXPECT_EQ(rb.ToYaml(true), yaml);
  EXPECT_DOUBLE_EQ(b.mvs.mpgc.drop_ncc, 0.45);
  EXPECT_EQ(b.fusion.bbox_max[2], std::optional<double>(3.5));
  EXPECT_FALSE(b.fusion.bbox_min[0].has_value());
  EXPECT_EQ(b.run.stages, "depth,fuse");
}

}  // namespace
}  // namespace wild_mvs
