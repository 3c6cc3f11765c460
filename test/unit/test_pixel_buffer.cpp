// Copyright wild_mvs authors. Driver image buffers and compressed bytes to
// linear RGB (no ROS): encodings, padded rows, Bayer demosaicing, malformed
// buffers named.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/io/pixel_buffer.h"

namespace wild_mvs {
namespace {

// An image buffer of zeros with its bytes.
struct Image {
  std::vector<uint8_t> bytes;
  PixelBuffer b;
  PixelBuffer View() {
    b.data = bytes.data();
    b.size = bytes.size();
    return b;
  }
};

Image MakeImage(int w, int h, const std::string& encoding,
                int bytes_per_pixel) {
  Image img;
  img.b.width = w;
  img.b.height = h;
  img.b.encoding = encoding;
  img.b.step = w * bytes_per_pixel;
  img.bytes.assign(static_cast<size_t>(img.b.step) * h, 0);
  return img;
}

std::string ErrorOf(Image img) {
  try {
    PixelsToLinearRgb(img.View(), true);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PixelBuffer, Encodings) {
  const float r = 200 / 255.f, g = 100 / 255.f, b = 50 / 255.f;
  struct Case {
    std::string encoding;
    std::vector<uint8_t> pixel;
  };
  const std::vector<Case> cases = {{"rgb8", {200, 100, 50}},
                                   {"bgr8", {50, 100, 200}},
                                   {"rgba8", {200, 100, 50, 255}},
                                   {"bgra8", {50, 100, 200, 255}}};
  for (const Case& c : cases) {
    Image img = MakeImage(3, 2, c.encoding, int(c.pixel.size()));
    std::memcpy(&img.bytes[img.b.step + c.pixel.size()], c.pixel.data(),
                c.pixel.size());  // pixel (1, 1)
    const cv::Mat out = PixelsToLinearRgb(img.View(), false);
    ASSERT_EQ(out.type(), CV_32FC3) << c.encoding;
    ASSERT_EQ(out.size(), cv::Size(3, 2)) << c.encoding;
    const cv::Vec3f v = out.at<cv::Vec3f>(1, 1);
    EXPECT_NEAR(v[0], r, 1e-6) << c.encoding;
    EXPECT_NEAR(v[1], g, 1e-6) << c.encoding;
    EXPECT_NEAR(v[2], b, 1e-6) << c.encoding;
    EXPECT_EQ(out.at<cv::Vec3f>(0, 0), cv::Vec3f(0, 0, 0)) << c.encoding;
    EXPECT_NE(out.data, img.bytes.data());
  }
  // mono8 mid grey, linearised.
  Image mono = MakeImage(4, 3, "mono8", 1);
  mono.bytes[5] = 128;
  cv::Mat out = PixelsToLinearRgb(mono.View(), true);
  EXPECT_NEAR(out.at<cv::Vec3f>(1, 1)[1], SrgbToLinear(128 / 255.0f), 1e-6);
  Image mono16 = MakeImage(3, 2, "mono16", 2);
  const uint16_t v16 = 30000;
  std::memcpy(&mono16.bytes[mono16.b.step + 2], &v16, 2);
  out = PixelsToLinearRgb(mono16.View(), false);
  EXPECT_NEAR(out.at<cv::Vec3f>(1, 1)[1], 30000 / 65535.f, 1e-5);
  // 32FC3 is RGB, linear already (linearize is not applied), and copied.
  Image f3 = MakeImage(2, 2, "32FC3", 12);
  const float px[3] = {0.25f, 0.5f, 0.75f};
  std::memcpy(&f3.bytes[12], px, sizeof(px));  // pixel (0, 1)
  out = PixelsToLinearRgb(f3.View(), true);
  EXPECT_EQ(out.at<cv::Vec3f>(0, 1), cv::Vec3f(0.25f, 0.5f, 0.75f));
  EXPECT_NE(out.data, f3.bytes.data());
  // Padded rows (step > width * 3) are honoured.
  Image padded = MakeImage(2, 2, "rgb8", 4);  // step = 8 > 6
  padded.bytes[8 + 3] = 255;                  // row 1, pixel 1, red
  out = PixelsToLinearRgb(padded.View(), false);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(1, 1)[0], 1.0f);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(1, 0)[0], 0.0f);
}

TEST(PixelBuffer, RejectsMalformed) {
  EXPECT_NE(ErrorOf(MakeImage(4, 3, "16UC1", 2)).find("'16UC1'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MakeImage(4, 3, "yuv422", 2)).find("'yuv422'"),
            std::string::npos);
  Image short_data = MakeImage(4, 3, "rgb8", 3);
  short_data.bytes.resize(10);
  EXPECT_NE(ErrorOf(short_data).find("data has 10 bytes"), std::string::npos);
  Image short_step = MakeImage(4, 3, "rgb8", 3);
  short_step.b.step = 5;
  EXPECT_NE(ErrorOf(short_step).find("step 5"), std::string::npos);
  EXPECT_NE(ErrorOf(MakeImage(0, 0, "rgb8", 3)).find("empty"),
            std::string::npos);
  Image big_endian = MakeImage(4, 3, "mono16", 2);
  big_endian.b.big_endian = true;
  EXPECT_NE(ErrorOf(big_endian).find("big-endian"), std::string::npos);
  Image odd_step = MakeImage(4, 3, "mono16", 2);
  odd_step.b.step = 9;
  odd_step.bytes.resize(27);
  EXPECT_NE(ErrorOf(odd_step).find("multiple"), std::string::npos);
  Image huge = MakeImage(1, 1, "mono8", 1);
  huge.b.width = kMaxBufferImageSide + 1;
  EXPECT_NE(ErrorOf(huge).find("too large"), std::string::npos);
  Image nan = MakeImage(2, 1, "32FC1", 4);
  const float bad = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.bytes.data(), &bad, 4);
  EXPECT_NE(ErrorOf(nan).find("non-finite"), std::string::npos);
  EXPECT_NE(ErrorOf(MakeImage(1, 4, "bayer_rggb8", 1)).find("2x2"),
            std::string::npos);
}

// A flat colour mosaiced in each ROS Bayer pattern (pattern letters name
// pixels (0,0) (0,1) (1,0) (1,1)) demosaics back to that colour: catches
// OpenCV's shifted COLOR_Bayer* names.
TEST(PixelBuffer, BayerDemosaic) {
  const int w = 16, h = 12;
  const double rgb[3] = {200, 100, 30};  // fraction of full scale: /255
  for (const std::string pattern : {"rggb", "bggr", "gbrg", "grbg"}) {
    for (int bits : {8, 16}) {
      const std::string e = "bayer_" + pattern + std::to_string(bits);
      const int bpp = bits / 8;
      Image img = MakeImage(w, h, e, bpp);
      const double scale = bits == 8 ? 1.0 : 257.0;  // 255 -> 65535
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const char ch = pattern[2 * (y % 2) + (x % 2)];
          const int c = ch == 'r' ? 0 : ch == 'g' ? 1 : 2;
          const double v = rgb[c] * scale;
          uint8_t* p = &img.bytes[y * img.b.step + x * bpp];
          if (bits == 8) {
            *p = static_cast<uint8_t>(v);
          } else {
            const uint16_t v16 = static_cast<uint16_t>(v);
            std::memcpy(p, &v16, 2);
          }
        }
      }
      const cv::Mat out = PixelsToLinearRgb(img.View(), false);
      ASSERT_EQ(out.type(), CV_32FC3) << e;
      ASSERT_EQ(out.size(), cv::Size(w, h)) << e;
      for (int y = 2; y < h - 2; ++y)
        for (int x = 2; x < w - 2; ++x)
          for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(out.at<cv::Vec3f>(y, x)[c], rgb[c] / 255.0, 2e-3)
                << e << " pixel (" << x << ", " << y << ") channel " << c;
    }
  }
  EXPECT_NE(ErrorOf(MakeImage(4, 4, "bayer_xyzw8", 1)).find("'bayer_xyzw8'"),
            std::string::npos);
}

TEST(PixelBuffer, Compressed) {
  cv::Mat bgr(6, 8, CV_8UC3, cv::Scalar(0, 0, 255));  // red
  std::vector<uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", bgr, png));
  const cv::Mat out = DecodeToLinearRgb(png.data(), png.size(), "png", true);
  ASSERT_EQ(out.type(), CV_32FC3);
  ASSERT_EQ(out.rows, 6);
  ASSERT_EQ(out.cols, 8);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(2, 3)[0], 1.0f);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(2, 3)[2], 0.0f);
  try {
    DecodeToLinearRgb(png.data(), 20, "png", true);  // truncated
    ADD_FAILURE() << "truncated png decoded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("format 'png'"), std::string::npos);
  }
  EXPECT_THROW(DecodeToLinearRgb(png.data(), 0, "png", true), Error);
}

}  // namespace
}  // namespace wild_mvs
