// Copyright wild_mvs authors.
#include "wild_mvs/stream/keyframe_store.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/stats.h"

namespace wild_mvs {

int KeyframeOwner(uint64_t stamp_ns, int worker_count) {
  Require(worker_count >= 1, "worker_count = ", worker_count, " must be >= 1");
  uint64_t z = stamp_ns + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return static_cast<int>(z % static_cast<uint64_t>(worker_count));
}

size_t Keyframe::Bytes() const {
  return image.empty() ? 0 : image.total() * image.elemSize();
}

void KeyframeSelectionOptions::Check() const {
  Require(std::isfinite(min_baseline) && min_baseline >= 0,
          "keyframe_min_baseline = ", min_baseline, " must be >= 0 (metres)");
  Require(std::isfinite(min_angle_deg) && min_angle_deg >= 0 &&
              min_angle_deg <= 180,
          "keyframe_min_angle_deg = ", min_angle_deg, " must be in [0, 180]");
}

void KeyframeStoreOptions::Check() const {
  Require(max_keyframes >= 2, "max_keyframes = ", max_keyframes,
          " must be >= 2");
  Require(std::isfinite(max_mb) && max_mb > 0, "max_keyframe_mb = ", max_mb,
          " must be > 0");
}

KeyframeStore::KeyframeStore(const KeyframeStoreOptions& options)
    : options_(options) {
  options_.Check();
}

static double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

bool KeyframeStore::IsNewKeyframe(
    const Camera& camera, const KeyframeSelectionOptions& selection) const {
  const KeyframePtr last = Newest();
  if (!last) return true;
  const double baseline = (camera.Center() - last->camera.Center()).norm();
  const double angle =
      AngleDeg(camera.ViewDirection(), last->camera.ViewDirection());
  return baseline >= selection.min_baseline || angle >= selection.min_angle_deg;
}

double KeyframeStore::Usefulness(const Keyframe& k) const {
  const KeyframePtr newest = Newest();
  if (!newest || newest->id == k.id) return std::numeric_limits<double>::max();
  // Median distance between consecutive keyframes: the unit of "far".
  std::vector<double> steps;
  const Keyframe* prev = nullptr;
  for (const auto& [id, kf] : keyframes_) {
    if (prev)
      steps.push_back((kf->camera.Center() - prev->camera.Center()).norm());
    prev = kf.get();
  }
  const double unit = steps.empty() ? 1.0 : std::max(Median(steps), 1e-9);
  const double distance =
      (k.camera.Center() - newest->camera.Center()).norm() / unit;
  const double angle =
      AngleDeg(k.camera.ViewDirection(), newest->camera.ViewDirection()) / 10.0;
  // Waiting keyframes rank above every done one.
  return (k.done() ? 0.0 : 1e12) - distance - angle;
}

std::vector<KeyframePtr> KeyframeStore::Add(KeyframePtr keyframe) {
  Require(keyframe != nullptr, "KeyframeStore::Add: null keyframe");
  Require(keyframes_.empty() || keyframe->id > keyframes_.rbegin()->first,
          "KeyframeStore::Add: keyframe id ", keyframe->id,
          " is not larger than the newest id held");
  bytes_ += keyframe->Bytes();
  keyframes_[keyframe->id] = std::move(keyframe);
  const size_t max_bytes = static_cast<size_t>(options_.max_mb * 1024 * 1024);
  std::vector<KeyframePtr> evicted;
  while (keyframes_.size() > 1 &&
         (keyframes_.size() > static_cast<size_t>(options_.max_keyframes) ||
          bytes_ > max_bytes)) {
    auto worst = keyframes_.end();
    double worst_score = std::numeric_limits<double>::max();
    for (auto it = keyframes_.begin(); it != keyframes_.end(); ++it) {
      const double s = Usefulness(*it->second);
      if (s < worst_score) {
        worst_score = s;
        worst = it;
      }
    }
    if (worst == keyframes_.end()) break;
    bytes_ -= worst->second->Bytes();
    evicted.push_back(worst->second);
    keyframes_.erase(worst);
  }
  return evicted;
}

KeyframePtr KeyframeStore::Get(uint32_t id) const {
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : it->second;
}

KeyframePtr KeyframeStore::Newest() const {
  return keyframes_.empty() ? nullptr : keyframes_.rbegin()->second;
}

std::vector<KeyframePtr> KeyframeStore::All() const {
  std::vector<KeyframePtr> out;
  out.reserve(keyframes_.size());
  for (const auto& [id, kf] : keyframes_) out.push_back(kf);
  return out;
}

void KeyframeStore::Clear() {
  keyframes_.clear();
  bytes_ = 0;
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     KeyframeSelectionOptions* o) {
  registry
      ->Add(OptionRegistry::Join(prefix, "keyframe_min_baseline"),
            &o->min_baseline, "m from the last keyframe that make a keyframe")
      .Min(0);
  registry
      ->Add(OptionRegistry::Join(prefix, "keyframe_min_angle_deg"),
            &o->min_angle_deg,
            "... or this viewing-angle change (degrees) makes a keyframe")
      .Min(0)
      .Max(180);
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     KeyframeStoreOptions* o) {
  registry
      ->Add(OptionRegistry::Join(prefix, "max_keyframes"), &o->max_keyframes,
            "keyframe store bound: count (least useful evicted)")
      .Min(2);
  registry
      ->Add(OptionRegistry::Join(prefix, "max_keyframe_mb"), &o->max_mb,
            "keyframe store bound: image megabytes")
      .Above(0);
}

}  // namespace wild_mvs
