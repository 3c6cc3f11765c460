// Copyright wild_mvs authors.
#include "wild_mvs/io/colmap_dense.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "byte_reader.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"

namespace wild_mvs {

namespace fs = std::filesystem;

namespace {

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Require(in.good(), path, ": cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  Require(!in.bad(), path, ": read error");
  return ss.str();
}

// Parses one "N&" field of an array header at *pos.
uint64_t ParseHeaderField(const std::string& data, size_t* pos,
                          const std::string& path, const char* what) {
  uint64_t v = 0;
  size_t digits = 0;
  while (*pos < data.size() && digits < 12 && data[*pos] >= '0' &&
         data[*pos] <= '9') {
    v = v * 10 + static_cast<uint64_t>(data[*pos] - '0');
    ++*pos;
    ++digits;
  }
  if (digits == 0 || *pos >= data.size() || data[*pos] != '&') {
    throw Error(Msg(path,
                    ": not a COLMAP array file (expected a header "
                    "'WIDTH&HEIGHT&CHANNELS&', bad ",
                    what, " at byte ", *pos, ")"));
  }
  ++*pos;
  return v;
}

void WriteLe32(std::ostream& os, uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);  // host is little-endian (x86-64, aarch64)
  os.write(b, 4);
}

}  // namespace

void WriteColmapArray(const std::string& path, const cv::Mat& image) {
  Require(
      !image.empty() && (image.type() == CV_32F || image.type() == CV_32FC3),
      path, ": a COLMAP array needs a non-empty CV_32F or CV_32FC3 image");
  const int w = image.cols, h = image.rows, c = image.channels();
  std::vector<cv::Mat> planes;
  cv::split(image, planes);
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << w << "&" << h << "&" << c << "&";
    for (int k = 0; k < c; ++k) {
      const cv::Mat plane =
          planes[k].isContinuous() ? planes[k] : planes[k].clone();
      os.write(reinterpret_cast<const char*>(plane.ptr<float>(0)),
               static_cast<std::streamsize>(sizeof(float)) * w * h);
    }
  });
}

cv::Mat ReadColmapArray(const std::string& path) {
  const std::string data = ReadWholeFile(path);
  size_t pos = 0;
  const uint64_t w = ParseHeaderField(data, &pos, path, "width");
  const uint64_t h = ParseHeaderField(data, &pos, path, "height");
  const uint64_t c = ParseHeaderField(data, &pos, path, "channels");
  Require(w > 0 && h > 0 && w <= 65536 && h <= 65536, path,
          ": invalid COLMAP array size ", w, "x", h,
          " (each side must be 1..65536)");
  Require(c >= 1 && c <= 4, path, ": COLMAP array has ", c,
          " channels (1..4 supported)");
  const uint64_t need = w * h * c * sizeof(float);
  const uint64_t have = data.size() - pos;
  Require(have == need, path, ": COLMAP array ", w, "x", h, "x", c, " needs ",
          need, " bytes of data after the header, file has ", have,
          have < need ? " (truncated)" : " (trailing bytes)");
  std::vector<cv::Mat> planes(c);
  for (uint64_t k = 0; k < c; ++k) {
    planes[k].create(static_cast<int>(h), static_cast<int>(w), CV_32F);
    std::memcpy(planes[k].ptr<float>(0), data.data() + pos + k * w * h * 4,
                w * h * 4);
  }
  cv::Mat out;
  cv::merge(planes, out);
  return out;
}

bool IsColmapDenseWorkspace(const std::string& dir) {
  std::error_code ec;
  const fs::path d(dir);
  return fs::is_directory(d / "images", ec) &&
         fs::is_directory(d / "stereo", ec) &&
         DetectColmapModel((d / "sparse").string()) != ColmapFormat::kNone;
}

const char* ColmapMapKindName(ColmapMapKind kind) {
  return kind == ColmapMapKind::kGeometric ? "geometric" : "photometric";
}

std::string ColmapDepthMapPath(const std::string& workspace,
                               const std::string& name, ColmapMapKind kind) {
  return (fs::path(workspace) / "stereo" / "depth_maps" /
          (name + "." + ColmapMapKindName(kind) + ".bin"))
      .string();
}

std::string ColmapNormalMapPath(const std::string& workspace,
                                const std::string& name, ColmapMapKind kind) {
  return (fs::path(workspace) / "stereo" / "normal_maps" /
          (name + "." + ColmapMapKindName(kind) + ".bin"))
      .string();
}

void WriteColmapDepthNormal(const std::string& workspace,
                            const std::string& name, ColmapMapKind kind,
                            const DepthMap& map) {
  const std::string depth_path = ColmapDepthMapPath(workspace, name, kind);
  Require(!map.depth.empty() && map.depth.type() == CV_32F, depth_path,
          ": depth map must be a non-empty CV_32F image");
  cv::Mat normal = map.normal;
  if (normal.empty()) normal = cv::Mat::zeros(map.depth.size(), CV_32FC3);
  Require(normal.type() == CV_32FC3 && normal.size() == map.depth.size(),
          ColmapNormalMapPath(workspace, name, kind),
          ": normal map must be CV_32FC3 of the depth's size");
  WriteColmapArray(depth_path, map.depth);
  WriteColmapArray(ColmapNormalMapPath(workspace, name, kind), normal);
}

void WriteColmapStereoConfig(const std::string& workspace,
                             const std::vector<ColmapStereoEntry>& entries) {
  const fs::path stereo = fs::path(workspace) / "stereo";
  WriteFileAtomically((stereo / "patch-match.cfg").string(),
                      [&](std::ostream& os) {
                        for (const ColmapStereoEntry& e : entries) {
                          os << e.name << "\n";
                          if (e.sources.empty()) {
                            os << "__auto__, 20\n";
                            continue;
                          }
                          for (size_t i = 0; i < e.sources.size(); ++i)
                            os << (i ? ", " : "") << e.sources[i];
                          os << "\n";
                        }
                      });
  WriteFileAtomically((stereo / "fusion.cfg").string(), [&](std::ostream& os) {
    for (const ColmapStereoEntry& e : entries) os << e.name << "\n";
  });
}

std::vector<ColmapStereoEntry> ReadColmapPatchMatchConfig(
    const std::string& path) {
  std::ifstream in(path);
  Require(in.good(), path, ": cannot open file");
  std::vector<ColmapStereoEntry> out;
  std::string line;
  int line_no = 0;
  bool want_name = true;
  auto trim = [](std::string s) {
    const size_t a = s.find_first_not_of(" \t\r");
    const size_t b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
  };
  while (std::getline(in, line)) {
    ++line_no;
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    if (want_name) {
      out.push_back({line, {}});
      want_name = false;
      continue;
    }
    want_name = true;
    if (line.rfind("__auto__", 0) == 0 || line == "__all__") continue;
    std::stringstream ss(line);
    std::string item;
    while (std::getline(ss, item, ',')) {
      item = trim(item);
      Require(!item.empty(), path, " line ", line_no,
              ": empty source image name");
      out.back().sources.push_back(item);
    }
  }
  Require(want_name, path, ": the last image ('",
          out.empty() ? std::string() : out.back().name,
          "') has no line of source images");
  return out;
}

void AddPointVisibility(const PointCloud& cloud, const DepthMap& map,
                        uint32_t view, double relative_tolerance,
                        std::vector<std::vector<uint32_t>>* visibility) {
  visibility->resize(cloud.size());
  if (map.empty()) return;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (AgreesWithDepthMap(cloud.xyz[i].cast<double>(), map,
                           relative_tolerance))
      (*visibility)[i].push_back(view);
  }
}

std::vector<std::vector<uint32_t>> ComputePointVisibility(
    const PointCloud& cloud, const std::vector<DepthMap>& maps,
    double relative_tolerance) {
  std::vector<std::vector<uint32_t>> vis(cloud.size());
  for (size_t v = 0; v < maps.size(); ++v)
    AddPointVisibility(cloud, maps[v], static_cast<uint32_t>(v),
                       relative_tolerance, &vis);
  return vis;
}

void WriteColmapFusedCloud(
    const std::string& path, const PointCloud& cloud,
    const std::vector<std::vector<uint32_t>>& visibility) {
  const size_t n = cloud.size();
  Require(visibility.size() == n, path, ": visibility has ", visibility.size(),
          " entries for ", n, " points");
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "ply\nformat binary_little_endian 1.0\nelement vertex " << n
       << "\nproperty float x\nproperty float y\nproperty float z\n"
          "property float nx\nproperty float ny\nproperty float nz\n"
          "property uchar red\nproperty uchar green\nproperty uchar blue\n"
          "end_header\n";
    std::vector<char> rec(27);
    for (size_t i = 0; i < n; ++i) {
      float f[6] = {
          cloud.xyz[i].x(), cloud.xyz[i].y(), cloud.xyz[i].z(), 0, 0, 0};
      if (cloud.has_normal()) {
        for (int k = 0; k < 3; ++k) f[3 + k] = cloud.normal[i][k];
      }
      std::memcpy(rec.data(), f, sizeof(f));
      for (int k = 0; k < 3; ++k) {
        const float c = cloud.has_rgb() ? cloud.rgb[i][k] : 0.5f;
        rec[24 + k] = static_cast<char>(static_cast<uint8_t>(
            std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)));
      }
      os.write(rec.data(), static_cast<std::streamsize>(rec.size()));
    }
  });
  WriteFileAtomically(path + ".vis", [&](std::ostream& os) {
    const uint64_t count = n;
    char b[8];
    std::memcpy(b, &count, 8);
    os.write(b, 8);
    for (const std::vector<uint32_t>& v : visibility) {
      WriteLe32(os, static_cast<uint32_t>(v.size()));
      for (uint32_t idx : v) WriteLe32(os, idx);
    }
  });
}

std::vector<std::vector<uint32_t>> ReadColmapVisibility(
    const std::string& path) {
  const std::string data = ReadWholeFile(path);
  io_detail::ByteReader r(data, path);
  const uint64_t n = r.Read<uint64_t>("number of points");
  r.RequireCount(n, 4, "number of points");
  std::vector<std::vector<uint32_t>> vis(n);
  for (uint64_t i = 0; i < n; ++i) {
    const uint32_t k = r.Read<uint32_t>("number of images of a point");
    r.RequireCount(k, 4, "number of images of a point");
    vis[i].resize(k);
    for (uint32_t j = 0; j < k; ++j) vis[i][j] = r.Read<uint32_t>("image");
  }
  Require(r.AtEnd(), path, ": ", r.remaining(),
          " trailing bytes after the last point");
  return vis;
}

}  // namespace wild_mvs
