// Copyright wild_mvs authors. Tests of the ImageCache's budget, Clear and
// uncached Load.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "wild_mvs/core/image.h"

namespace wild_mvs {
namespace {

// 100 x 100 CV_32FC3 images (120,000 bytes) whose value is the view.
struct CountingLoader {
  int* calls;
  cv::Mat operator()(int view) const {
    ++*calls;
    return cv::Mat(100, 100, CV_32FC3, cv::Scalar::all(view));
  }
};
constexpr size_t kImageBytes = 100 * 100 * 3 * sizeof(float);

TEST(ImageCache, BudgetClearAndUncachedLoad) {
  int calls = 0;
  // Room for 3 images.
  ImageCache cache(CountingLoader{&calls}, 3.5 * kImageBytes / (1024 * 1024));
  for (int v = 0; v < 5; ++v) cache.Get(v);
  EXPECT_EQ(calls, 5);
  EXPECT_EQ(cache.bytes(), 3 * kImageBytes);  // LRU within the budget
  cache.Get(4);                               // cached: no load
  EXPECT_EQ(calls, 5);

  // Load: from the loader every time, never cached.
  const cv::Mat a = cache.Load(7);
  EXPECT_EQ(a.at<cv::Vec3f>(0, 0)[0], 7.f);
  cache.Load(7);
  EXPECT_EQ(calls, 7);
  EXPECT_EQ(cache.bytes(), 3 * kImageBytes);
  cache.Get(4);  // Load evicted nothing
  EXPECT_EQ(calls, 7);

  // Clear: nothing cached, the next Get loads again; an image held by a
  // caller lives on.
  std::shared_ptr<const cv::Mat> held = cache.Get(3);
  cache.Clear();
  EXPECT_EQ(cache.bytes(), 0u);
  EXPECT_EQ(held->at<cv::Vec3f>(0, 0)[0], 3.f);
  cache.Get(4);
  EXPECT_EQ(calls, 8);
  EXPECT_EQ(cache.bytes(), kImageBytes);
  // The peak counts an inserted image before the LRU evicts for it.
  EXPECT_EQ(cache.peak_bytes(), 4 * kImageBytes);
}

}  // namespace
}  // namespace wild_mvs
