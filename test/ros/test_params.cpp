// Copyright wild_mvs authors. ROS parameters -> option structs.
#include <gtest/gtest.h>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {
namespace {

TEST(Params, DefaultsAreValid) {
  MapParamSource none;
  const DepthNodeOptions d = ReadDepthNodeOptions(none);
  EXPECT_EQ(d.world_frame, "world");
  EXPECT_EQ(d.pose_source, "tf");
  EXPECT_TRUE(d.stream.use_tracker);
  EXPECT_EQ(d.stream.mvs.global.num_neighbors, 10);  // paper default kept
  const FusionNodeOptions f = ReadFusionNodeOptions(none);
  EXPECT_EQ(f.fusion.min_support, FusionOptions().min_support);
  EXPECT_EQ(f.on_new_session, "keep");
}

TEST(Params, ValuesReachTheCoreOptions) {
  MapParamSource p({{"world_frame", std::string("map")},
                    {"keyframe_min_baseline", 0.2},
                    {"keyframe_min_angle_deg", 7},  // int for a double: ok
                    {"worker_index", 1},
                    {"worker_count", 3},
                    {"sparse_source", std::string("topic")},
                    {"mvs/num_neighbors", 6},
                    {"mvs/min_ncc", 0.35},
                    {"mvs/optimize_color_scale", false},
                    {"tracker/max_features", 1500},
                    {"max_keyframe_mb", 128.0}});
  const DepthNodeOptions d = ReadDepthNodeOptions(p);
  EXPECT_EQ(d.world_frame, "map");
  EXPECT_DOUBLE_EQ(d.stream.keyframes.min_baseline, 0.2);
  EXPECT_DOUBLE_EQ(d.stream.keyframes.min_angle_deg, 7.0);
  EXPECT_EQ(d.stream.worker_index, 1);
  EXPECT_EQ(d.stream.worker_count, 3);
  EXPECT_FALSE(d.stream.use_tracker);
  EXPECT_EQ(d.stream.mvs.global.num_neighbors, 6);
  EXPECT_DOUBLE_EQ(d.stream.mvs.local.min_ncc, 0.35);
  EXPECT_FALSE(d.stream.mvs.mpgc.optimize_color_scale);
  EXPECT_EQ(d.stream.tracker.features.max_features, 1500);
  EXPECT_DOUBLE_EQ(d.stream.store.max_mb, 128.0);

  MapParamSource q({{"publish_period", 0.5},
                    {"output_path", std::string("/tmp/x.ply")},
                    {"fusion/min_support", 2},
                    {"fusion/depth_tolerance", 0.02}});
  const FusionNodeOptions f = ReadFusionNodeOptions(q);
  EXPECT_DOUBLE_EQ(f.publish_period, 0.5);
  EXPECT_EQ(f.output_path, "/tmp/x.ply");
  EXPECT_EQ(f.fusion.min_support, 2);
  EXPECT_DOUBLE_EQ(f.fusion.depth_tolerance, 0.02);
}

std::string ErrorOf(const MapParamSource& p) {
  try {
    ReadDepthNodeOptions(p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Params, BadValuesNameTheParameter) {
  EXPECT_NE(ErrorOf(MapParamSource({{"worker_index", 2}})).find("worker_index"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"pose_source", std::string("gps")}}))
                .find("pose_source"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"tf_timeout", std::string("fast")}}))
                .find("tf_timeout"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf(MapParamSource({{"max_keyframes", 2.5}})).find("max_keyframes"),
      std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"mvs/min_ncc", 3.0}})).find("ncc"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"linearize", 1}})).find("linearize"),
            std::string::npos);
  MapParamSource f({{"fusion/min_support", 0}});
  EXPECT_THROW(ReadFusionNodeOptions(f), Error);
  // Reset policy of the fusion node: keep or reset, nothing else.
  EXPECT_EQ(ReadFusionNodeOptions(
                MapParamSource({{"on_new_session", std::string("reset")}}))
                .on_new_session,
            "reset");
  try {
    ReadFusionNodeOptions(
        MapParamSource({{"on_new_session", std::string("clear")}}));
    ADD_FAILURE() << "on_new_session 'clear' accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("on_new_session"), std::string::npos);
  }
}

TEST(Params, UnknownParametersAreListed) {
  MapParamSource p(
      {{"keyframe_min_angel", 5.0}, {"world_frame", std::string("w")}});
  const auto unknown = UnknownDepthNodeParams(p);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "keyframe_min_angel");
  EXPECT_TRUE(
      UnknownFusionNodeParams(MapParamSource({{"fusion/min_support", 3}}))
          .empty());
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs
