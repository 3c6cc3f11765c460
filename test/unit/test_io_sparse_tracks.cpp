// Copyright wild_mvs authors. OUT/sparse/tracks.txt (io/sparse_tracks_file.h):
// an exact round trip, and refusal of a file written for other views or
// options; truncated files are errors naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/sparse_tracks_file.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

Scene TwoViewScene() {
  Scene s;
  for (const char* name : {"a b.jpg", "sub/c.png"}) {
    View v;
    v.name = name;
    v.camera.width = 640;
    v.camera.height = 480;
    s.views.push_back(v);
  }
  SparsePoint p;
  p.xyz = Eigen::Vector3d(1.0 / 3.0, -2e-7, 12345.678901234567);
  p.rgb = Eigen::Vector3f(0.1f, 1.0f / 3.0f, 0.9999999f);
  p.error = 0.123456789012345678;
  p.track.push_back({0, Eigen::Vector2d(10.000000000000002, 0.1), 2.5});
  p.track.push_back({1, Eigen::Vector2d(639.99999999999989, 1e-300), 0});
  s.points.push_back(p);
  p.track.clear();  // a point without observations survives too
  s.points.push_back(p);
  return s;
}

TEST(SparseTracksFile, RoundTripIsExact) {
  const std::string dir = testing::MakeTempDir("wild_mvs_tracks");
  const std::string path = dir + "/sparse/tracks.txt";
  const Scene s = TwoViewScene();
  const std::vector<std::string> f = {"image.max_image_size 320",
                                      "dataset.mask_dir "};
  WriteSparseTracks(path, s, f);
  std::vector<SparsePoint> points;
  std::string why;
  ASSERT_TRUE(ReadSparseTracks(path, s, f, &points, &why)) << why;
  ASSERT_EQ(points.size(), s.points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].xyz, s.points[i].xyz);
    EXPECT_EQ(points[i].rgb, s.points[i].rgb);
    EXPECT_EQ(points[i].error, s.points[i].error);
    ASSERT_EQ(points[i].track.size(), s.points[i].track.size());
    for (size_t j = 0; j < points[i].track.size(); ++j) {
      EXPECT_EQ(points[i].track[j].view, s.points[i].track[j].view);
      EXPECT_EQ(points[i].track[j].xy, s.points[i].track[j].xy);
      EXPECT_EQ(points[i].track[j].scale, s.points[i].track[j].scale);
    }
  }

  // Other options or other views: refused, saying why.
  EXPECT_FALSE(ReadSparseTracks(
      path, s, {"image.max_image_size 640", "dataset.mask_dir "}, &points,
      &why));
  EXPECT_NE(why.find("image.max_image_size: '320' in the file, '640' now"),
            std::string::npos)
      << why;
  Scene other = s;
  other.views[1].camera.width = 320;
  EXPECT_FALSE(ReadSparseTracks(path, other, f, &points, &why));
  EXPECT_NE(why.find("sub/c.png"), std::string::npos) << why;
  other = s;
  other.views.pop_back();
  EXPECT_FALSE(ReadSparseTracks(path, other, f, &points, &why));

  // Truncated: an error naming the file.
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  {
    std::ofstream out(path, std::ios::trunc);
    out << text.substr(0, text.size() - 10);
  }
  try {
    ReadSparseTracks(path, s, f, &points, &why);
    ADD_FAILURE() << "no error for a truncated file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace wild_mvs
