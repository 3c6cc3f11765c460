// Copyright wild_mvs authors.
#include "wild_mvs/io/depth_map_io.h"

#include <filesystem>
#include <iomanip>
#include <limits>

#include "text_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/pfm.h"
#include "wild_mvs/io/preview.h"

namespace wild_mvs {

namespace fs = std::filesystem;
using io_detail::ParseDouble;
using io_detail::ParseInt;
using io_detail::RequireTokens;
using io_detail::Split;

DepthMapPaths MakeDepthMapPaths(const std::string& out_dir,
                                const std::string& stem) {
  const fs::path o(out_dir);
  DepthMapPaths p;
  p.depth = (o / "depth" / (stem + ".pfm")).string();
  p.normal = (o / "normal" / (stem + ".pfm")).string();
  p.confidence = (o / "confidence" / (stem + ".pfm")).string();
  p.camera = (o / "cameras" / (stem + ".txt")).string();
  p.preview_depth = (o / "preview" / (stem + "_depth.png")).string();
  p.preview_confidence = (o / "preview" / (stem + "_confidence.png")).string();
  p.preview_normal = (o / "preview" / (stem + "_normal.png")).string();
  return p;
}

void WriteDepthMapCamera(const std::string& path, const Camera& c,
                         const std::vector<std::string>& neighbor_names) {
  for (const std::string& n : neighbor_names)
    Require(!n.empty() && n.find('\n') == std::string::npos, path,
            ": invalid neighbour name '", n, "'");
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "# wild_mvs depth map camera: width height / fx fy cx cy / R (3 "
          "rows, world-to-camera) / t / N / N neighbour names\n"
       << std::setprecision(std::numeric_limits<double>::max_digits10);
    os << c.width << " " << c.height << "\n"
       << c.fx << " " << c.fy << " " << c.cx << " " << c.cy << "\n";
    for (int r = 0; r < 3; ++r)
      os << c.R(r, 0) << " " << c.R(r, 1) << " " << c.R(r, 2) << "\n";
    os << c.t.x() << " " << c.t.y() << " " << c.t.z() << "\n"
       << neighbor_names.size() << "\n";
    for (const std::string& n : neighbor_names) os << n << "\n";
  });
}

Camera ReadDepthMapCamera(const std::string& path,
                          std::vector<std::string>* neighbor_names) {
  io_detail::TextFile f(path);
  std::string line;
  auto next = [&](size_t n, const char* what) {
    if (!f.NextData(&line))
      throw Error(Msg(path, " line ", f.line() + 1,
                      ": truncated file: expected ", what));
    const auto tok = Split(line);
    RequireTokens(tok, n, true, f.Where(), what);
    return tok;
  };
  Camera c;
  auto tok = next(2, "width height");
  c.width = static_cast<int>(ParseInt(tok[0], f.Where(), "width"));
  c.height = static_cast<int>(ParseInt(tok[1], f.Where(), "height"));
  tok = next(4, "fx fy cx cy");
  c.fx = ParseDouble(tok[0], f.Where(), "fx");
  c.fy = ParseDouble(tok[1], f.Where(), "fy");
  c.cx = ParseDouble(tok[2], f.Where(), "cx");
  c.cy = ParseDouble(tok[3], f.Where(), "cy");
  for (int r = 0; r < 3; ++r) {
    tok = next(3, "rotation row");
    for (int k = 0; k < 3; ++k)
      c.R(r, k) = ParseDouble(tok[k], f.Where(), "rotation");
  }
  tok = next(3, "translation");
  for (int k = 0; k < 3; ++k)
    c.t[k] = ParseDouble(tok[k], f.Where(), "translation");
  c.Validate(f.Where());
  c.R = NearestRotation(c.R);
  tok = next(1, "number of neighbours");
  const long long n = ParseInt(tok[0], f.Where(), "number of neighbours");
  Require(n >= 0 && n < 100000, f.Where(), ": invalid number of neighbours ",
          n);
  std::vector<std::string> names;
  for (long long i = 0; i < n; ++i) {
    if (!f.Next(&line))
      throw Error(Msg(path, " line ", f.line() + 1,
                      ": truncated file: expected neighbour ", i + 1, " of ",
                      n));
    const std::string name = io_detail::Trim(line);
    Require(!name.empty(), f.Where(), ": empty neighbour name");
    names.push_back(name);
  }
  if (neighbor_names) *neighbor_names = std::move(names);
  return c;
}

void WriteDepthMapFiles(const std::string& out_dir, const std::string& stem,
                        const DepthMap& map,
                        const std::vector<std::string>& neighbor_names,
                        bool previews) {
  const DepthMapPaths p = MakeDepthMapPaths(out_dir, stem);
  Require(!map.depth.empty() && map.depth.type() == CV_32F, p.depth,
          ": depth map must be a non-empty CV_32F image");
  Require(
      map.depth.cols == map.camera.width && map.depth.rows == map.camera.height,
      p.depth, ": depth is ", map.depth.cols, "x", map.depth.rows,
      " but its camera is ", map.camera.width, "x", map.camera.height);
  if (!map.normal.empty())
    Require(
        map.normal.type() == CV_32FC3 && map.normal.size() == map.depth.size(),
        p.normal, ": normal map must be CV_32FC3 of the depth's size");
  if (!map.confidence.empty())
    Require(map.confidence.type() == CV_32F &&
                map.confidence.size() == map.depth.size(),
            p.confidence,
            ": confidence map must be CV_32F of the depth's size");
  WritePfm(p.depth, map.depth);
  if (!map.normal.empty()) WritePfm(p.normal, map.normal);
  if (!map.confidence.empty()) WritePfm(p.confidence, map.confidence);
  if (previews) {
    WriteImageAtomically(p.preview_depth, DepthPreview(map.depth));
    if (!map.confidence.empty())
      WriteImageAtomically(p.preview_confidence,
                           ConfidencePreview(map.confidence));
    if (!map.normal.empty())
      WriteImageAtomically(p.preview_normal, NormalPreview(map.normal));
  }
  WriteDepthMapCamera(p.camera, map.camera, neighbor_names);  // last
}

DepthMapFiles ReadDepthMapFiles(const std::string& out_dir,
                                const std::string& stem) {
  const DepthMapPaths p = MakeDepthMapPaths(out_dir, stem);
  DepthMapFiles out;
  out.map.camera = ReadDepthMapCamera(p.camera, &out.neighbor_names);
  out.map.depth = ReadPfm(p.depth);
  const cv::Size size(out.map.camera.width, out.map.camera.height);
  Require(out.map.depth.type() == CV_32F, p.depth,
          ": depth must have 1 channel");
  Require(out.map.depth.size() == size, p.depth, ": depth is ",
          out.map.depth.cols, "x", out.map.depth.rows, " but ", p.camera,
          " says ", size.width, "x", size.height);
  std::error_code ec;
  if (fs::exists(p.normal, ec)) {
    out.map.normal = ReadPfm(p.normal);
    Require(out.map.normal.type() == CV_32FC3 && out.map.normal.size() == size,
            p.normal, ": normal map must have 3 channels and size ", size.width,
            "x", size.height);
  }
  if (fs::exists(p.confidence, ec)) {
    out.map.confidence = ReadPfm(p.confidence);
    Require(out.map.confidence.type() == CV_32F &&
                out.map.confidence.size() == size,
            p.confidence, ": confidence map must have 1 channel and size ",
            size.width, "x", size.height);
  }
  return out;
}

DepthMap ReadDepthMapFiles(const std::string& out_dir, const std::string& stem,
                           const Scene& scene) {
  DepthMapFiles f = ReadDepthMapFiles(out_dir, stem);
  const std::string cam = MakeDepthMapPaths(out_dir, stem).camera;
  for (size_t i = 0; i < scene.views.size(); ++i)
    if (scene.views[i].Stem() == stem) f.map.view = static_cast<int>(i);
  Require(f.map.view >= 0, cam, ": no view of the scene has the stem '", stem,
          "'");
  for (const std::string& n : f.neighbor_names) {
    const int v = scene.FindView(n);
    Require(v >= 0, cam, ": neighbour '", n, "' is not a view of the scene");
    f.map.neighbors.push_back(v);
  }
  return f.map;
}

bool DepthMapFilesExist(const std::string& out_dir, const std::string& stem) {
  const DepthMapPaths p = MakeDepthMapPaths(out_dir, stem);
  std::error_code ec;
  return fs::exists(p.depth, ec) && fs::exists(p.camera, ec);
}

}  // namespace wild_mvs
