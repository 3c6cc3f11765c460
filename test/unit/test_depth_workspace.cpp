// Copyright wild_mvs authors. The workspaces of pipeline/depth_workspace.h
// that hold no files: CachedDepthWorkspace in front of an in-memory one
// that counts its reads. A cached map is read from the workspace behind
// once, the cache holds no more maps than its capacity, a write replaces
// what it held, and threads reading at once each get the map they asked
// for.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/pipeline/depth_workspace.h"

namespace wild_mvs {
namespace {

using Stage = DepthWorkspace::Stage;

class CountingWorkspace : public MemoryDepthWorkspace {
 public:
  std::shared_ptr<const DepthMap> Read(Stage stage, int key) const override {
    ++reads;
    return MemoryDepthWorkspace::Read(stage, key);
  }
  mutable std::atomic<int> reads{0};
};

// A 4x3 map of view `key` whose every depth is `depth`.
ViewResult MapOf(int key, float depth) {
  ViewResult r;
  r.map.view = key;
  r.map.depth = cv::Mat(3, 4, CV_32F, cv::Scalar(depth));
  r.map.normal = cv::Mat(3, 4, CV_32FC3, cv::Scalar(0, 0, -1));
  r.map.confidence = cv::Mat(3, 4, CV_32F, cv::Scalar(0.5));
  return r;
}

TEST(CachedDepthWorkspace, ReadsEachMapOnceWhileItIsHeld) {
  CountingWorkspace inner;
  for (int k = 0; k < 3; ++k) inner.Write(Stage::kRaw, k, MapOf(k, 1.0f + k));
  CachedDepthWorkspace cached(&inner, 3);
  for (int round = 0; round < 4; ++round)
    for (int k = 0; k < 3; ++k) {
      const auto map = cached.Read(Stage::kRaw, k);
      EXPECT_EQ(map->view, k);
      EXPECT_EQ(map->depth.at<float>(1, 2), 1.0f + k);
    }
  EXPECT_EQ(inner.reads.load(), 3);
  EXPECT_TRUE(cached.Has(Stage::kRaw, 2));
  EXPECT_FALSE(cached.Has(Stage::kFinal, 2));
  EXPECT_THROW(cached.Read(Stage::kFinal, 2), Error);
}

TEST(CachedDepthWorkspace, HoldsNoMoreMapsThanItsCapacity) {
  CountingWorkspace inner;
  for (int k = 0; k < 3; ++k) inner.Write(Stage::kRaw, k, MapOf(k, 1.0f));
  CachedDepthWorkspace cached(&inner, 2);
  cached.Read(Stage::kRaw, 0);
  cached.Read(Stage::kRaw, 1);
  cached.Read(Stage::kRaw, 0);  // held: 0 is now the most recent
  EXPECT_EQ(inner.reads.load(), 2);
  cached.Read(Stage::kRaw, 2);  // drops 1, the least recently read
  cached.Read(Stage::kRaw, 0);
  EXPECT_EQ(inner.reads.load(), 3);
  cached.Read(Stage::kRaw, 1);
  EXPECT_EQ(inner.reads.load(), 4);
  EXPECT_THROW(CachedDepthWorkspace(&inner, 0), Error);
  EXPECT_THROW(CachedDepthWorkspace(nullptr, 2), Error);
}

TEST(CachedDepthWorkspace, AWriteReplacesTheMapItHeld) {
  CountingWorkspace inner;
  inner.Write(Stage::kRaw, 5, MapOf(5, 2.0f));
  CachedDepthWorkspace cached(&inner, 4);
  EXPECT_EQ(cached.Read(Stage::kRaw, 5)->depth.at<float>(0, 0), 2.0f);
  cached.Write(Stage::kRaw, 5, MapOf(5, 3.0f));
  EXPECT_EQ(inner.Read(Stage::kRaw, 5)->depth.at<float>(0, 0), 3.0f);
  EXPECT_EQ(cached.Read(Stage::kRaw, 5)->depth.at<float>(0, 0), 3.0f);
  EXPECT_EQ(cached.Samples(Stage::kRaw, 5), 12);
}

TEST(CachedDepthWorkspace, ThreadsReadingAtOnceGetTheirMaps) {
  CountingWorkspace inner;
  constexpr int kViews = 12;
  for (int k = 0; k < kViews; ++k)
    inner.Write(Stage::kRaw, k, MapOf(k, 1.0f + k));
  CachedDepthWorkspace cached(&inner, 4);
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 2000; ++i) {
        const int k = (i * 7 + t * 3) % kViews;
        const auto map = cached.Read(Stage::kRaw, k);
        if (map->view != k || map->depth.at<float>(2, 3) != 1.0f + k) ++wrong;
      }
    });
  for (std::thread& th : threads) th.join();
  EXPECT_EQ(wrong.load(), 0);
}

}  // namespace
}  // namespace wild_mvs
