// Copyright wild_mvs authors. PFM, 16-bit PNG depth and preview tests.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/pfm.h"
#include "wild_mvs/io/png_depth.h"
#include "wild_mvs/io/preview.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
void WriteBytes(const std::string& path, const std::string& s) {
  std::ofstream out(path, std::ios::binary);
  out << s;
}

TEST(Pfm, RoundTripOneAndThreeChannels) {
  const std::string dir = testing::MakeTempDir("pfm");
  cv::Mat a(7, 5, CV_32F);
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < a.cols; ++c) a.at<float>(r, c) = r * 10.f + c + 0.25f;
  a.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
  WritePfm(dir + "/a.pfm", a);
  const cv::Mat b = ReadPfm(dir + "/a.pfm");
  ASSERT_EQ(b.type(), CV_32F);
  ASSERT_EQ(b.size(), a.size());
  EXPECT_TRUE(std::isnan(b.at<float>(0, 0)));
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < a.cols; ++c)
      if (r || c) {
        EXPECT_EQ(b.at<float>(r, c), a.at<float>(r, c));
      }
  cv::Mat n(3, 4, CV_32FC3);
  cv::randu(n, -1, 1);
  WritePfm(dir + "/n.pfm", n);
  const cv::Mat m = ReadPfm(dir + "/n.pfm");
  ASSERT_EQ(m.type(), CV_32FC3);
  EXPECT_EQ(cv::norm(m, n, cv::NORM_INF), 0);
  fs::remove_all(dir);
}

// The file layout follows the format: header, -1 scale, rows bottom-to-top.
TEST(Pfm, FileLayoutIsBottomToTopLittleEndian) {
  const std::string dir = testing::MakeTempDir("pfm_layout");
  cv::Mat a = (cv::Mat_<float>(2, 2) << 1, 2, 3, 4);  // top row 1 2
  WritePfm(dir + "/a.pfm", a);
  const std::string bytes = ReadBytes(dir + "/a.pfm");
  const std::string header = "Pf\n2 2\n-1\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 16);
  float v[4];
  std::memcpy(v, bytes.data() + header.size(), 16);
  EXPECT_EQ(v[0], 3);  // bottom row first
  EXPECT_EQ(v[1], 4);
  EXPECT_EQ(v[2], 1);
  EXPECT_EQ(v[3], 2);
  // A hand-made big-endian file (positive scale).
  std::string be = "Pf\n2 1\n1.0\n";
  for (float f : {1.5f, -2.0f}) {
    char c[4];
    std::memcpy(c, &f, 4);
    be += std::string{c[3], c[2], c[1], c[0]};
  }
  WriteBytes(dir + "/be.pfm", be);
  const cv::Mat b = ReadPfm(dir + "/be.pfm");
  EXPECT_EQ(b.at<float>(0, 0), 1.5f);
  EXPECT_EQ(b.at<float>(0, 1), -2.0f);
  fs::remove_all(dir);
}

TEST(Pfm, MalformedFilesGiveErrors) {
  const std::string dir = testing::MakeTempDir("pfm_bad");
  const std::string p = dir + "/x.pfm";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "truncated"},
      {"P6\n2 2\n255\n", "not a PFM"},
      {"Pf\n2\n", "truncated"},
      {"Pf\n-2 2\n-1\n", "invalid PFM size"},
      {"Pf\n2 2\n0\n", "non-zero"},
      {"Pf\n2 2\nnan\n", "not a finite"},
      {"Pf\n2 2\n-1\n" + std::string(15, 'a'), "truncated PFM"},
      {"PF\n2 2\n-1\n" + std::string(16, 'a'), "truncated PFM"},
      {"Pf\n999999 999999\n-1\n", "truncated PFM"},
  };
  for (const auto& [content, expect] : cases) {
    WriteBytes(p, content);
    try {
      ReadPfm(p);
      ADD_FAILURE() << "no error for '" << content.substr(0, 20) << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("x.pfm"), std::string::npos);
    }
  }
  EXPECT_THROW(ReadPfm(dir + "/missing.pfm"), Error);
  fs::remove_all(dir);
}

TEST(PngDepth, MillimetreRoundTrip) {
  const std::string dir = testing::MakeTempDir("png16");
  cv::Mat d = (cv::Mat_<float>(2, 3) << 0, 1.2344f, 65.535f, 70.f,
               std::numeric_limits<float>::infinity(), 0.0004f);
  const int dropped = WriteDepthPng16(dir + "/d.png", d);
  EXPECT_EQ(dropped, 2);  // 70 m does not fit, 0.4 mm rounds to 0
  const cv::Mat raw = cv::imread(dir + "/d.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16U);
  EXPECT_EQ(raw.at<uint16_t>(0, 1), 1234);
  EXPECT_EQ(raw.at<uint16_t>(0, 2), 65535);
  const cv::Mat r = ReadDepthPng16(dir + "/d.png");
  EXPECT_FLOAT_EQ(r.at<float>(0, 0), 0);
  EXPECT_NEAR(r.at<float>(0, 1), 1.234, 1e-6);
  EXPECT_EQ(r.at<float>(1, 0), 0);
  EXPECT_EQ(r.at<float>(1, 1), 0);
  EXPECT_THROW(ReadDepthPng16(dir + "/none.png"), Error);
  fs::remove_all(dir);
}

TEST(Preview, DepthConfidenceNormalColours) {
  cv::Mat d(10, 100, CV_32F, cv::Scalar(0));
  for (int c = 0; c < 100; ++c) d.col(c).setTo(c == 0 ? 0.f : 1.0f + c);
  const cv::Mat p = DepthPreview(d);
  ASSERT_EQ(p.type(), CV_8UC3);
  EXPECT_EQ(p.at<cv::Vec3b>(5, 0), cv::Vec3b(0, 0, 0));  // unknown
  // TURBO: near is blue-ish, far is red-ish.
  const cv::Vec3b near = p.at<cv::Vec3b>(5, 3), far = p.at<cv::Vec3b>(5, 97);
  EXPECT_GT(near[0], near[2]);
  EXPECT_GT(far[2], far[0]);
  const cv::Mat conf = (cv::Mat_<float>(1, 3) << 0, 0.5f, 2.f);
  const cv::Mat cp = ConfidencePreview(conf);
  EXPECT_EQ(cp.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(cp.at<uint8_t>(0, 1), 128);
  EXPECT_EQ(cp.at<uint8_t>(0, 2), 255);
  cv::Mat n(1, 2, CV_32FC3, cv::Scalar(0, 0, 0));
  n.at<cv::Vec3f>(0, 1) = cv::Vec3f(0, 0, -1);
  const cv::Mat np = NormalPreview(n);
  EXPECT_EQ(np.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(np.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 128, 128));  // B G R
}

}  // namespace
}  // namespace wild_mvs
