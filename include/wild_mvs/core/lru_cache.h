// Copyright wild_mvs authors. A least-recently-used map with a cost per
// entry, the one bounded cache under the image cache, the noise-profile
// cache, the cached depth workspace and the fusion's map cache: each entry
// costs what its owner says (bytes, or 1 for a count), and Evict drops the
// least recently used entries while the total exceeds a budget. Not
// thread-safe: the owners hold their own lock around it.
#pragma once

#include <cstddef>
#include <list>
#include <map>
#include <utility>

namespace wild_mvs {

template <class Key, class Value>
class LruCache {
 public:
  // The value of `key`, which becomes the most recently used entry; null
  // when absent.
  Value* Find(const Key& key) {
    auto it = index_.find(key);
    if (it == index_.end()) return nullptr;
    order_.splice(order_.begin(), order_, it->second);
    return &it->second->value;
  }

  bool Contains(const Key& key) const { return index_.count(key) > 0; }

  // Adds `key` as the most recently used entry, at `cost`; false (nothing
  // changed) when it is present already.
  bool Insert(const Key& key, Value value, size_t cost) {
    if (Contains(key)) return false;
    order_.push_front(Entry{key, std::move(value), cost});
    index_.emplace(key, order_.begin());
    cost_ += cost;
    return true;
  }

  // Drops least recently used entries while the total cost exceeds
  // `budget` and more than `keep` entries are left; an entry for which
  // pinned(value) is true stays (the next older one goes instead).
  template <class Pinned>
  void Evict(size_t budget, size_t keep, Pinned&& pinned) {
    for (auto e = order_.end();
         cost_ > budget && order_.size() > keep && e != order_.begin();) {
      --e;
      if (pinned(e->value)) continue;
      cost_ -= e->cost;
      index_.erase(e->key);
      e = order_.erase(e);
    }
  }
  void Evict(size_t budget, size_t keep = 0) {
    Evict(budget, keep, [](const Value&) { return false; });
  }

  // Drops `key` when present.
  void Erase(const Key& key) {
    auto it = index_.find(key);
    if (it == index_.end()) return;
    cost_ -= it->second->cost;
    order_.erase(it->second);
    index_.erase(it);
  }

  void Clear() {
    order_.clear();
    index_.clear();
    cost_ = 0;
  }

  size_t size() const { return order_.size(); }
  // The entries' total cost.
  size_t cost() const { return cost_; }

 private:
  struct Entry {
    Key key;
    Value value;
    size_t cost;
  };
  std::list<Entry> order_;  // most recently used first
  std::map<Key, typename std::list<Entry>::iterator> index_;
  size_t cost_ = 0;
};

}  // namespace wild_mvs
