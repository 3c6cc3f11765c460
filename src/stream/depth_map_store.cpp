// Copyright wild_mvs authors.
#include "wild_mvs/stream/depth_map_store.h"

#include <stdlib.h>

#include <exception>
#include <filesystem>
#include <system_error>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/depth_map_io.h"

namespace wild_mvs {

namespace fs = std::filesystem;

DepthMapStore::DepthMapStore(double max_mb, const std::string& spill_dir)
    : max_bytes_(static_cast<size_t>(max_mb * 1048576.0)) {
  if (spill_dir.empty()) {
    std::string tmpl =
        (fs::temp_directory_path() / "wild_mvs_fusion_XXXXXX").string();
    Require(mkdtemp(tmpl.data()) != nullptr,
            "fusion node: cannot create a temporary folder for spilled maps");
    dir_ = tmpl;
    own_dir_ = true;
  } else {
    dir_ = spill_dir;
    fs::create_directories(dir_);
  }
}

DepthMapStore::~DepthMapStore() {
  if (own_dir_) {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
}

void DepthMapStore::Hold(int v, DepthMap map, cv::Mat image,
                         const ErrorCallback& on_error) {
  Held h;
  h.bytes = HeldBytes(map, image);
  h.image = std::move(image);
  h.map = std::make_shared<const DepthMap>(std::move(map));
  bytes_ += h.bytes;
  held_[v] = std::move(h);
  order_.push_back(v);
  while (bytes_ > max_bytes_ && order_.size() > 1) {
    const int old = order_.front();
    order_.pop_front();
    Held& o = held_[old];
    if (!o.map) continue;
    try {
      WriteDepthMapFiles(dir_, Stem(old), *o.map, {}, false);
      o.map.reset();
      o.image.release();
      bytes_ -= o.bytes;
      ++spilled_;
    } catch (const std::exception& e) {
      if (on_error) on_error("cannot spill a depth map to " + dir_, e.what());
      break;
    }
  }
}

std::shared_ptr<const DepthMap> DepthMapStore::Map(int v) const {
  auto it = held_.find(v);
  Require(it != held_.end(), "fusion node: unknown view ", v);
  if (it->second.map) return it->second.map;
  DepthMapFiles f = ReadDepthMapFiles(dir_, Stem(v));
  f.map.view = v;
  return std::make_shared<const DepthMap>(std::move(f.map));
}

cv::Mat DepthMapStore::Image(int v) const {
  auto it = held_.find(v);
  return it == held_.end() ? cv::Mat() : it->second.image;
}

bool DepthMapStore::InMemory(int v) const {
  auto it = held_.find(v);
  return it != held_.end() && it->second.map != nullptr;
}

void DepthMapStore::Clear() {
  held_.clear();
  order_.clear();
  bytes_ = 0;
}

}  // namespace wild_mvs
