// Copyright wild_mvs authors. The depth maps a live run published, as a
// reconstruct folder that `wild_mvs eval depth` scores (bench/run_live.sh).
//
//   bench_live_depth_maps REC.bag DATASET OUT [--revision 0|1]
//
// Reads every wild_mvs/DepthView of REC.bag (the depth node's depth_view,
// recorded by reconstruct_bag.launch record:=REC.bag), keeps per keyframe
// its final revision (--revision N: its revision N), finds the dataset
// view it shows (the view whose camera centre is nearest, within 1 mm) and
// writes OUT/depth/<stem>.pfm with its camera, as `wild_mvs reconstruct`
// does. Prints the keyframes, views and revisions found. Exit 1 with a
// message naming the file on bad input.
//
// Also prints how late the maps came, from the bag's record times (the
// launch's clock: sim time, which the bag plays at its rate): per keyframe
// the seconds from its image stamp to its first depth view, and how many
// newer keyframes got their first depth view before its revision 1 and
// before its final revision.
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <wild_mvs/DepthView.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace {

int Run(int argc, char** argv) {
  const bool ok =
      argc == 4 ||
      (argc == 6 && std::string(argv[4]) == "--revision" &&
       (std::string(argv[5]) == "0" || std::string(argv[5]) == "1"));
  if (!ok) {
    std::cerr << "usage: bench_live_depth_maps REC.bag DATASET OUT "
                 "[--revision 0|1]\n";
    return 2;
  }
  const std::string bag_path = argv[1], out = argv[3];
  const int wanted = argc == 6 ? std::stoi(argv[5]) : -1;  // -1: the final
  DatasetOptions dataset;
  dataset.path = argv[2];
  dataset.check_images = false;
  const Scene scene = LoadDataset(dataset);

  std::map<uint64_t, wild_mvs::DepthViewConstPtr> by_stamp;
  // Per keyframe stamp: record time of its first depth view; order of first
  // depth views; per keyframe the count of first views before its revision
  // 1 and before its final revision.
  std::map<uint64_t, double> first_at;
  std::map<uint64_t, int> first_order, early_after, final_after;
  int messages = 0, revised = 0;
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw Error(Msg(bag_path, ": cannot read the bag: ", e.what()));
  }
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    const wild_mvs::DepthViewConstPtr v = m.instantiate<wild_mvs::DepthView>();
    if (!v) continue;
    ++messages;
    revised += v->revision > 0;
    const uint64_t key = v->header.stamp.toNSec();
    if (!first_at.count(key)) {
      first_at[key] = m.getTime().toSec() - v->header.stamp.toSec();
      first_order[key] = static_cast<int>(first_order.size());
    }
    const int newer =
        static_cast<int>(first_order.size()) - 1 - first_order[key];
    if (v->revision == 1) early_after[key] = newer;
    if (v->final_revision) final_after[key] = newer;
    auto it = by_stamp.find(key);
    const bool take =
        wanted >= 0
            ? (static_cast<int>(v->revision) == wanted && it == by_stamp.end())
            : (it == by_stamp.end() || v->revision >= it->second->revision);
    if (take) by_stamp[key] = v;
  }
  Require(messages > 0, bag_path, ": no wild_mvs/DepthView message");
  int written = 0;
  for (const auto& [stamp, msg] : by_stamp) {
    const DepthMap map = ros1::DepthMapFromDepthView(*msg);
    int best = -1;
    double best_d = 1e-3;
    for (size_t i = 0; i < scene.views.size(); ++i) {
      const double d =
          (scene.views[i].camera.Center() - map.camera.Center()).norm();
      if (d < best_d) {
        best_d = d;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) {
      std::cerr << "keyframe " << msg->keyframe_id
                << ": no dataset view at its camera centre (skipped)\n";
      continue;
    }
    WriteDepthMapFiles(out, scene.views[best].Stem(), map, {}, false);
    ++written;
  }
  std::vector<double> lat;
  for (const auto& [k, t] : first_at) lat.push_back(t);
  std::sort(lat.begin(), lat.end());
  if (!lat.empty()) {
    std::cout << "first depth view after its image: median "
              << lat[lat.size() / 2] << " s, max " << lat.back() << " s\n";
  }
  for (const auto& [name, after] :
       {std::make_pair("revision 1", &early_after),
        std::make_pair("final revision", &final_after)}) {
    std::vector<int> lag;
    for (const auto& [k, n] : *after) lag.push_back(n);
    std::sort(lag.begin(), lag.end());
    if (lag.empty()) continue;
    std::cout << name << " after " << lag[lag.size() / 2]
              << " newer keyframes' first views (median), " << lag.back()
              << " (max); " << lag.size() << " of " << first_at.size()
              << " keyframes have a " << name << "\n";
  }
  std::cout << messages << " depth views (" << revised << " revisions), "
            << by_stamp.size() << " keyframes, " << written << " of "
            << scene.views.size() << " views written to " << out << "\n";
  return 0;
}

}  // namespace
}  // namespace wild_mvs

int main(int argc, char** argv) {
  try {
    return wild_mvs::Run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "bench_live_depth_maps: " << e.what() << "\n";
    return 1;
  }
}
