// Copyright wild_mvs authors. PLY writer / reader tests.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/ply.h"

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
  std::ofstream(path, std::ios::binary) << s;
}

PointCloud MakeCloud(size_t n, bool all) {
  PointCloud c;
  for (size_t i = 0; i < n; ++i) {
    c.xyz.emplace_back(0.5f * i, -1.25f * i, 3.0f + i);
    if (!all) continue;
    c.normal.push_back(Eigen::Vector3f(i, 1, -2).normalized());
    c.rgb.emplace_back(i / 10.0f, 1.0f, 0.0f);
    c.confidence.push_back(0.1f * i);
    c.support.push_back(static_cast<uint16_t>(1000 * i));
  }
  return c;
}

// Points [begin, end) of c.
PointCloud MakeCloudRange(const PointCloud& c, size_t begin, size_t end) {
  PointCloud r;
  auto slice = [&](const auto& from, auto* to) {
    if (!from.empty()) to->assign(from.begin() + begin, from.begin() + end);
  };
  slice(c.xyz, &r.xyz);
  slice(c.normal, &r.normal);
  slice(c.rgb, &r.rgb);
  slice(c.confidence, &r.confidence);
  slice(c.support, &r.support);
  return r;
}

TEST(Ply, CloudRoundTripAllAttributes) {
  const std::string d = testing::MakeTempDir("ply");
  const PointCloud c = MakeCloud(10, true);
  WritePly(d + "/c.ply", c);
  const std::string bytes = ReadBytes(d + "/c.ply");
  EXPECT_EQ(bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(bytes.find("property uchar red"), std::string::npos);
  EXPECT_NE(bytes.find("property ushort support"), std::string::npos);
  // 10 vertices x (12 + 12 + 3 + 4 + 2) bytes after the header.
  EXPECT_EQ(bytes.size() - (bytes.find("end_header\n") + 11), 10u * 33);
  const PointCloud r = ReadPlyCloud(d + "/c.ply");
  ASSERT_EQ(r.size(), 10u);
  ASSERT_TRUE(r.has_normal() && r.has_rgb() && r.has_confidence() &&
              r.has_support());
  for (size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(r.xyz[i], c.xyz[i]);
    EXPECT_EQ(r.normal[i], c.normal[i]);
    EXPECT_NEAR(r.rgb[i][0], c.rgb[i][0], 0.5 / 255 + 1e-6);
    EXPECT_EQ(r.rgb[i][1], 1.0f);
    EXPECT_EQ(r.confidence[i], c.confidence[i]);
    EXPECT_EQ(r.support[i], c.support[i]);
  }
  // xyz only.
  WritePly(d + "/p.ply", MakeCloud(4, false));
  const PointCloud p = ReadPlyCloud(d + "/p.ply");
  EXPECT_EQ(p.size(), 4u);
  EXPECT_FALSE(p.has_normal() || p.has_rgb() || p.has_confidence() ||
               p.has_support());
  // Inconsistent attribute sizes are refused.
  PointCloud bad = MakeCloud(3, true);
  bad.confidence.pop_back();
  EXPECT_THROW(WritePly(d + "/bad.ply", bad), Error);
  EXPECT_FALSE(fs::exists(d + "/bad.ply"));
  fs::remove_all(d);
}

// The chunked writer gives the bytes of WritePly of the whole cloud, for
// chunk sizes that do and do not divide the size, and for no points.
TEST(Ply, ChunkedWriteEqualsWholeWrite) {
  const std::string d = testing::MakeTempDir("ply_chunked");
  for (bool all : {true, false}) {
    for (size_t n : {size_t{0}, size_t{1}, size_t{10}, size_t{12}}) {
      const PointCloud c = MakeCloud(n, all);
      WritePly(d + "/whole.ply", c);
      const std::string whole = ReadBytes(d + "/whole.ply");
      for (size_t chunk : {size_t{1}, size_t{3}, size_t{4}, size_t{100}}) {
        std::vector<std::pair<size_t, size_t>> asked;
        WritePlyChunked(
            d + "/chunked.ply", n,
            [&](size_t begin, size_t end) {
              asked.emplace_back(begin, end);
              return MakeCloudRange(c, begin, end);
            },
            chunk);
        EXPECT_EQ(ReadBytes(d + "/chunked.ply"), whole)
            << "n " << n << " chunk " << chunk << " all " << all;
        // In order, each range once, one chunk at a time.
        size_t next = 0;
        for (const auto& [b, e] : asked) {
          EXPECT_EQ(b, next);
          EXPECT_LE(e - b, chunk);
          next = e;
        }
        EXPECT_EQ(next, n);
      }
    }
  }
  // A source that changes its attributes or gives a wrong count is refused
  // and leaves no file.
  const PointCloud c = MakeCloud(6, true);
  EXPECT_THROW(WritePlyChunked(
                   d + "/bad.ply", 6,
                   [&](size_t b, size_t e) {
                     PointCloud r = MakeCloudRange(c, b, e);
                     if (b > 0) r.rgb.clear();
                     return r;
                   },
                   3),
               Error);
  EXPECT_THROW(
      WritePlyChunked(
          d + "/bad.ply", 6,
          [&](size_t b, size_t) { return MakeCloudRange(c, b, b); }, 3),
      Error);
  EXPECT_FALSE(fs::exists(d + "/bad.ply"));
  fs::remove_all(d);
}

TEST(Ply, MeshRoundTrip) {
  const std::string d = testing::MakeTempDir("ply_mesh");
  Mesh m;
  m.vertices = MakeCloud(5, true);
  m.faces = {{0, 1, 2}, {2, 3, 4}, {4, 0, 2}};
  WritePly(d + "/m.ply", m);
  const std::string bytes = ReadBytes(d + "/m.ply");
  EXPECT_NE(
      bytes.find("element face 3\nproperty list uchar int vertex_indices"),
      std::string::npos);
  const Mesh r = ReadPlyMesh(d + "/m.ply");
  EXPECT_EQ(r.faces, m.faces);
  EXPECT_EQ(r.vertices.size(), 5u);
  EXPECT_EQ(ReadPlyCloud(d + "/m.ply").size(), 5u);
  m.faces.emplace_back(0, 1, 5);
  EXPECT_THROW(WritePly(d + "/bad.ply", m), Error);
  fs::remove_all(d);
}

TEST(Ply, ReadsAsciiAndBigEndianAndQuads) {
  const std::string d = testing::MakeTempDir("ply_ascii");
  WriteBytes(d + "/a.ply",
             "ply\r\nformat ascii 1.0\r\ncomment hi\r\n"
             "element vertex 4\r\nproperty double x\r\nproperty double y\r\n"
             "property double z\r\nproperty int extra\r\n"
             "property uchar red\r\nproperty uchar green\r\nproperty uchar "
             "blue\r\n"
             "element face 1\r\nproperty list uchar uint vertex_index\r\n"
             "end_header\r\n"
             "0 0 0 7 255 0 0\r\n1 0 0 7 0 255 0\r\n1 1 0 7 0 0 255\r\n"
             "0 1 0.5 7 10 10 10\r\n4 0 1 2 3\r\n");
  const Mesh m = ReadPlyMesh(d + "/a.ply");
  ASSERT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.vertices.xyz[3], Eigen::Vector3f(0, 1, 0.5f));
  EXPECT_EQ(m.vertices.rgb[1], Eigen::Vector3f(0, 1, 0));
  ASSERT_EQ(m.faces.size(), 2u);  // quad -> 2 triangles
  EXPECT_EQ(m.faces[1], Eigen::Vector3i(0, 2, 3));
  // No newline after the last value.
  WriteBytes(d + "/n.ply",
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n1 2 3");
  EXPECT_EQ(ReadPlyCloud(d + "/n.ply").xyz[0], Eigen::Vector3f(1, 2, 3));
  // Big endian float xyz.
  std::string be =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\n"
      "property float x\nproperty float y\nproperty float z\n"
      "end_header\n";
  for (float f : {1.5f, -2.0f, 4.0f}) {
    char c[4];
    std::memcpy(c, &f, 4);
    be += std::string{c[3], c[2], c[1], c[0]};
  }
  WriteBytes(d + "/be.ply", be);
  EXPECT_EQ(ReadPlyCloud(d + "/be.ply").xyz[0], Eigen::Vector3f(1.5f, -2, 4));
  fs::remove_all(d);
}

TEST(Ply, MalformedFilesGiveErrors) {
  const std::string d = testing::MakeTempDir("ply_bad");
  WritePly(d + "/good.ply", MakeCloud(50, true));
  const std::string good = ReadBytes(d + "/good.ply");
  const std::string p = d + "/x.ply";
  auto expect = [&](const std::string& content, const std::string& what) {
    WriteBytes(p, content);
    try {
      ReadPlyMesh(p);
      ADD_FAILURE() << "no error, expected '" << what << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("x.ply"), std::string::npos);
    }
  };
  // Every truncation of the binary body.
  const size_t body = good.find("end_header\n") + 11;
  for (size_t len = body; len < good.size(); len += 7)
    expect(good.substr(0, len), "");
  expect(good.substr(0, body - 11), "no end_header");
  expect(good.substr(0, body - 5), "unknown header keyword");
  expect("plx\n", "not a PLY");
  std::string huge = good;
  huge.replace(huge.find("vertex 50"), 9, "vertex 99999999999");
  expect(huge, "does not fit");
  expect(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nend_header\n1 2\n",
      "lacks x, y or z");
  expect(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n1 2 nan\n",
      "non-finite");
  expect(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n1 2 abc\n",
      "line 8");
  expect(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 1 1\n3 0 1 2\n",
      "refers to vertex 2");
  expect("ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY");
  expect(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\n"
      "end_header\n",
      "unknown property type");
  fs::remove_all(d);
}

}  // namespace
}  // namespace wild_mvs
