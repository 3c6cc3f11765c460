// Copyright wild_mvs authors.
#include "wild_mvs/core/scene.h"

#include <unordered_set>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

std::string View::Stem() const {
  std::string s = name;
  const auto dot = s.find_last_of('.');
  const auto slash = s.find_last_of("/\\");
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash))
    s.erase(dot);
  for (char& c : s)
    if (c == '/' || c == '\\' || c == ' ') c = '_';
  return s;
}

int Scene::FindView(const std::string& name) const {
  for (size_t i = 0; i < views.size(); ++i)
    if (views[i].name == name) return static_cast<int>(i);
  return -1;
}

std::vector<std::vector<int>> Scene::PointsPerView() const {
  std::vector<std::vector<int>> out(views.size());
  for (size_t p = 0; p < points.size(); ++p)
    for (const Observation& o : points[p].track)
      if (o.view >= 0 && o.view < static_cast<int>(views.size()) &&
          (out[o.view].empty() || out[o.view].back() != static_cast<int>(p)))
        out[o.view].push_back(static_cast<int>(p));  // once per view
  return out;
}

void Scene::Validate() const {
  Require(!views.empty(), source, ": the model has no views");
  std::unordered_set<std::string> names;
  for (const View& v : views) {
    Require(names.insert(v.name).second, source, ": duplicate image name '",
            v.name, "'");
    v.camera.Validate(source + ": image '" + v.name + "'");
  }
  for (size_t p = 0; p < points.size(); ++p) {
    const SparsePoint& pt = points[p];
    Require(pt.xyz.allFinite(), source, ": point ", p, " is not finite");
    for (const Observation& o : pt.track)
      Require(o.view >= 0 && o.view < static_cast<int>(views.size()), source,
              ": point ", p, " has a track entry for missing image ", o.view);
  }
}

}  // namespace wild_mvs
