// Copyright wild_mvs authors.
#include "wild_mvs/cli/scene_setup.h"

#include <algorithm>
#include <filesystem>
#include <set>

namespace wild_mvs {
namespace cli {

namespace fs = std::filesystem;

DatasetOptions MakeDatasetOptions(const std::string& path, const Args& args) {
  DatasetOptions o;
  o.path = path;
  o.model_dir = args.Get("model");
  o.images_dir = args.Get("images");
  try {
    o.format = ParseDatasetFormat(args.Get("format", "auto"), "--format");
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  o.Check();  // a missing dataset folder is an input error (status 1)
  return o;
}

int LimitImageSize(Scene* scene, int max_size) {
  if (max_size <= 0) return 0;
  std::vector<Eigen::Vector2d> factor(scene->views.size(),
                                      Eigen::Vector2d(1, 1));
  std::vector<double> scale(scene->views.size(), 1.0);
  int changed = 0;
  for (size_t i = 0; i < scene->views.size(); ++i) {
    View& v = scene->views[i];
    const int fw = v.file_width > 0 ? v.file_width : v.camera.width;
    const int fh = v.file_height > 0 ? v.file_height : v.camera.height;
    const int longest = std::max(fw, fh);
    if (longest <= max_size) continue;
    const Camera file_cam = v.camera.Resized(fw, fh);
    const Camera small =
        file_cam.Scaled(static_cast<double>(max_size) / longest);
    factor[i] =
        Eigen::Vector2d(static_cast<double>(small.width) / v.camera.width,
                        static_cast<double>(small.height) / v.camera.height);
    scale[i] = 0.5 * (factor[i].x() + factor[i].y());
    v.file_width = fw;
    v.file_height = fh;
    v.camera = small;
    ++changed;
  }
  if (changed == 0) return 0;
  for (SparsePoint& p : scene->points) {
    for (Observation& o : p.track) {
      if (o.view < 0 || o.view >= static_cast<int>(factor.size())) continue;
      // Continuous pixel coordinates with the (0.5, 0.5) centre convention
      // scale about the image corner, like the intrinsics.
      o.xy = o.xy.cwiseProduct(factor[o.view]);
      o.scale *= scale[o.view];
    }
  }
  return changed;
}

std::vector<int> SelectViews(const Scene& scene, const std::string& list) {
  std::vector<int> out;
  if (list.empty()) {
    for (size_t i = 0; i < scene.views.size(); ++i) {
      out.push_back(static_cast<int>(i));
    }
    return out;
  }
  std::set<int> seen;
  for (const std::string& item : SplitList(list)) {
    int index = scene.FindView(item);
    for (size_t i = 0; index < 0 && i < scene.views.size(); ++i) {
      if (scene.views[i].Stem() == item) index = static_cast<int>(i);
    }
    if (index < 0) {
      std::string names;
      for (size_t i = 0; i < scene.views.size() && i < 8; ++i) {
        names += (i ? ", " : "") + scene.views[i].name;
      }
      if (scene.views.size() > 8) names += ", ...";
      throw UsageError(Msg("--views: no view named '", item,
                           "' in the dataset (views: ", names, ")"));
    }
    if (seen.insert(index).second) out.push_back(index);
  }
  Require(!out.empty(), "--views: the list is empty");
  return out;
}

Shard ParseShard(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return UsageError(Msg("--shard '", text, "': ", why,
                          " (expected K/N with 1 <= K <= N, e.g. 2/8)"));
  };
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw bad("no '/'");
  const auto number = [&](const std::string& s, const char* what) {
    if (s.empty() || s.size() > 9 ||
        s.find_first_not_of("0123456789") != std::string::npos) {
      throw bad(Msg(what, " is not a positive integer"));
    }
    return std::stoi(s);
  };
  Shard shard;
  shard.index = number(text.substr(0, slash), "K");
  shard.count = number(text.substr(slash + 1), "N");
  if (shard.count < 1) throw bad("N must be at least 1");
  if (shard.index < 1 || shard.index > shard.count) {
    throw bad("K must be in 1..N");
  }
  return shard;
}

std::vector<int> ShardViews(std::vector<int> views, const Shard& shard) {
  std::sort(views.begin(), views.end());
  std::vector<int> out;
  for (size_t i = static_cast<size_t>(shard.index - 1); i < views.size();
       i += static_cast<size_t>(shard.count)) {
    out.push_back(views[i]);
  }
  return out;
}

}  // namespace cli
}  // namespace wild_mvs
