// Copyright wild_mvs authors.
#include "wild_mvs/io/strecha.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "text_util.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {

namespace fs = std::filesystem;
using io_detail::ParseDouble;
using io_detail::ParseInt;
using io_detail::RequireTokens;
using io_detail::Split;
using io_detail::TextFile;

Camera ReadStrechaCamera(const std::string& path) {
  TextFile f(path);
  std::string line;
  auto next = [&](size_t n, const char* what) {
    if (!f.NextData(&line))
      throw Error(Msg(path, " line ", f.line() + 1,
                      ": truncated file: expected ", what));
    auto tok = Split(line);
    RequireTokens(tok, n, true, f.Where(), what);
    std::vector<double> v;
    for (const auto& t : tok) v.push_back(ParseDouble(t, f.Where(), what));
    return v;
  };
  Eigen::Matrix3d K, R;
  for (int r = 0; r < 3; ++r) {
    const auto v = next(3, "K row");
    for (int c = 0; c < 3; ++c) K(r, c) = v[c];
  }
  const std::string kw = Msg(path, " lines 1-3");
  Require(K(2, 2) != 0, kw, ": K33 must be non-zero");
  K /= K(2, 2);
  Require(std::abs(K(1, 0)) < 1e-9 && std::abs(K(2, 0)) < 1e-9 &&
              std::abs(K(2, 1)) < 1e-9,
          kw, ": K is not upper triangular with last row (0 0 1)");
  Require(K(0, 0) > 0 && K(1, 1) > 0, kw,
          ": focal length must be positive (fx=", K(0, 0), " fy=", K(1, 1),
          ")");
  Require(std::abs(K(0, 1)) <= 1e-6 * K(0, 0), kw, ": K has skew ", K(0, 1),
          " (not supported)");
  const auto dist = next(3, "radial distortion (3 numbers)");
  Require(dist[0] == 0 && dist[1] == 0 && dist[2] == 0, f.Where(),
          ": non-zero radial distortion is not supported (undistort the "
          "images first)");
  for (int r = 0; r < 3; ++r) {
    const auto v = next(3, "R row");
    for (int c = 0; c < 3; ++c) R(r, c) = v[c];
  }
  const std::string rw = Msg(path, " lines ", f.line() - 2, "-", f.line());
  const double orth = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
  Require(orth < 1e-3 && R.determinant() > 0, rw,
          ": rotation is not orthonormal (|R R^T - I| = ", orth,
          ", det = ", R.determinant(), ")");
  const auto C = next(3, "camera centre");
  if (!f.NextData(&line))
    throw Error(Msg(path, " line ", f.line() + 1,
                    ": truncated file: expected width height"));
  const auto wh = Split(line);
  RequireTokens(wh, 2, true, f.Where(), "width height");
  const long long w = ParseInt(wh[0], f.Where(), "width");
  const long long h = ParseInt(wh[1], f.Where(), "height");
  Require(w > 0 && h > 0 && w <= 1000000 && h <= 1000000, f.Where(),
          ": invalid image size ", w, "x", h);
  Camera c;
  c.width = static_cast<int>(w);
  c.height = static_cast<int>(h);
  c.fx = K(0, 0);
  c.fy = K(1, 1);
  c.cx = K(0, 2) + 0.5;
  c.cy = K(1, 2) + 0.5;
  c.R = NearestRotation(R.transpose());
  c.t = -c.R * Eigen::Vector3d(C[0], C[1], C[2]);
  c.Validate(path);
  return c;
}

Scene ReadStrechaCameras(const std::string& cameras_dir,
                         const std::string& images_dir) {
  std::error_code ec;
  Require(fs::is_directory(cameras_dir, ec), cameras_dir,
          ": camera folder does not exist");
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(cameras_dir, ec))
    if (e.path().extension() == ".camera") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  Require(!files.empty(), cameras_dir, ": empty model: no *.camera files");
  Scene scene;
  scene.source = Msg("Strecha cameras ", cameras_dir);
  for (const std::string& file : files) {
    View v;
    v.name = fs::path(file).stem().string();  // "0000.jpg"
    v.image_path = (fs::path(images_dir) / v.name).string();
    v.camera = ReadStrechaCamera(file);
    scene.views.push_back(std::move(v));
  }
  scene.Validate();
  return scene;
}

}  // namespace wild_mvs
