// Copyright wild_mvs authors. Tests of SIFT feature extraction: the pixel
// convention (camera.h: pixel centres at +0.5), positions and scales under
// downscaling, the feature cap, descriptor normalisation and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/features.h"

namespace wild_mvs {
namespace {

// Linear grey image with Gaussian blobs centred at continuous positions in
// the camera.h convention: pixel (col, row) samples at (col + .5, row + .5).
cv::Mat Blobs(int w, int h, const std::vector<Eigen::Vector2d>& centres,
              double sigma) {
  cv::Mat img(h, w, CV_32FC3);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      double v = 0.1;
      for (const Eigen::Vector2d& m : centres) {
        const double dx = c + 0.5 - m.x(), dy = r + 0.5 - m.y();
        v += 0.7 * std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
      }
      img.at<cv::Vec3f>(r, c) = cv::Vec3f(v, v, v);
    }
  }
  return img;
}

// Index of the feature nearest to p.
int Nearest(const Features& f, const Eigen::Vector2d& p) {
  int best = -1;
  double bd = 1e9;
  for (int i = 0; i < f.size(); ++i) {
    const double d = (f.xy[i].cast<double>() - p).norm();
    if (d < bd) {
      bd = d;
      best = i;
    }
  }
  return best;
}

TEST(Features, BlobCentreInPixelConvention) {
  const std::vector<Eigen::Vector2d> centres = {
      {60.3, 70.7}, {150.0, 40.0}, {200.5, 150.5}, {90.8, 180.2}};
  const double sigma = 4.0;
  const cv::Mat img = Blobs(256, 224, centres, sigma);
  for (double downscale : {1.0, 2.0}) {
    FeatureOptions opt;
    opt.max_image_size = downscale > 1 ? 128 : 0;  // 256 px: factor 2
    const Features f = ExtractFeatures(img, opt);
    ASSERT_GE(f.size(), 4) << "downscale " << downscale;
    for (const Eigen::Vector2d& c : centres) {
      const int i = Nearest(f, c);
      ASSERT_GE(i, 0);
      // Sub-pixel accurate; an error of the +0.5 convention would show as
      // 0.25-0.7 px.
      EXPECT_LT((f.xy[i].cast<double>() - c).norm(), 0.08)
          << "blob " << c.transpose() << " downscale " << downscale << " found "
          << f.xy[i].transpose();
      // SIFT size ~ blob scale in full-resolution pixels (the DoG peak of a
      // Gaussian blob of sigma s is at scale ~s; size = 2 * scale * ...).
      EXPECT_GT(f.scale[i], 1.5 * sigma);
      EXPECT_LT(f.scale[i], 12 * sigma);
    }
  }
}

TEST(Features, MaxImageSizeShrinksLargeImages) {
  const std::vector<Eigen::Vector2d> centres = {{100.3, 80.6}, {300.5, 200.5}};
  const cv::Mat img = Blobs(400, 300, centres, 5.0);
  FeatureOptions opt;
  opt.max_image_size = 200;  // factor 2
  const Features f = ExtractFeatures(img, opt);
  for (const Eigen::Vector2d& c : centres) {
    const int i = Nearest(f, c);
    ASSERT_GE(i, 0);
    EXPECT_LT((f.xy[i].cast<double>() - c).norm(), 0.15);
  }
  FeatureOptions bad;
  bad.max_image_size = 10;
  EXPECT_THROW(bad.Check(), Error);
}

TEST(Features, DownscaleKeepsScaleInFullResolutionPixels) {
  const std::vector<Eigen::Vector2d> centres = {{100.5, 100.5}};
  const cv::Mat img = Blobs(200, 200, centres, 5.0);
  FeatureOptions o1, o2;
  o2.max_image_size = 100;  // factor 2
  const Features f1 = ExtractFeatures(img, o1), f2 = ExtractFeatures(img, o2);
  const int i1 = Nearest(f1, centres[0]), i2 = Nearest(f2, centres[0]);
  ASSERT_GE(i1, 0);
  ASSERT_GE(i2, 0);
  EXPECT_NEAR(f2.scale[i2] / f1.scale[i1], 1.0, 0.25);
}

TEST(Features, CapDescriptorsAndDeterminism) {
  // A random texture has many features.
  cv::Mat noise(240, 320, CV_32FC1);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.5);
  cv::Mat img;
  cv::cvtColor(noise, img, cv::COLOR_GRAY2RGB);
  FeatureOptions opt;
  opt.max_features = 0;
  const Features all = ExtractFeatures(img, opt);
  ASSERT_GT(all.size(), 200);
  opt.max_features = 100;
  const Features capped = ExtractFeatures(img, opt);
  ASSERT_EQ(capped.size(), 100);
  EXPECT_EQ(capped.descriptors.rows, 100);
  EXPECT_EQ(capped.descriptors.type(), CV_8U);
  EXPECT_EQ(capped.scale.size(), 100u);
  EXPECT_EQ(capped.rgb.size(), 100u);
  EXPECT_GT(capped.bytes(), 100u * 128);
  // Unit-norm descriptors (up to byte quantisation).
  for (int i = 0; i < capped.size(); ++i) {
    const uint8_t* d = capped.descriptors.ptr<uint8_t>(i);
    double n = 0;
    for (int k = 0; k < 128; ++k) n += static_cast<double>(d[k]) * d[k];
    EXPECT_NEAR(std::sqrt(n) / Features::kDescriptorScale, 1.0, 0.02);
    EXPECT_EQ(DescriptorDistanceSquared(d, d), 0);
  }
  // Same input, same output.
  const Features again = ExtractFeatures(img, opt);
  ASSERT_EQ(again.size(), capped.size());
  for (int i = 0; i < again.size(); ++i) {
    EXPECT_EQ(again.xy[i], capped.xy[i]);
  }
  EXPECT_EQ(cv::norm(again.descriptors, capped.descriptors, cv::NORM_L1), 0);
  // Inside the image, in the pixel convention.
  for (const Eigen::Vector2f& p : all.xy) {
    EXPECT_GE(p.x(), 0);
    EXPECT_GE(p.y(), 0);
    EXPECT_LE(p.x(), 320);
    EXPECT_LE(p.y(), 240);
  }
  // A mask removes the features where it is zero.
  cv::Mat mask(240, 320, CV_8U, cv::Scalar(0));
  mask(cv::Rect(0, 0, 160, 240)).setTo(255);
  opt.max_features = 0;
  const Features left = ExtractFeatures(img, opt, mask);
  ASSERT_GT(left.size(), 50);
  for (const Eigen::Vector2f& p : left.xy) EXPECT_LT(p.x(), 170);
}

TEST(Features, RejectsBadInput) {
  EXPECT_THROW(ExtractFeatures(cv::Mat(), FeatureOptions()), Error);
  EXPECT_THROW(ExtractFeatures(cv::Mat(10, 10, CV_16UC3), FeatureOptions()),
               Error);
  FeatureOptions bad;
  bad.max_image_size = 10;
  EXPECT_THROW(ExtractFeatures(cv::Mat(10, 10, CV_8UC1), bad), Error);
  EXPECT_THROW(ExtractFeatures(cv::Mat(10, 10, CV_8UC1), FeatureOptions(),
                               cv::Mat(5, 5, CV_8UC1)),
               Error);
}

}  // namespace
}  // namespace wild_mvs
