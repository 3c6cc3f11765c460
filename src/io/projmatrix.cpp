// Copyright wild_mvs authors.
#include "wild_mvs/io/projmatrix.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>

#include "text_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/image_size.h"

namespace wild_mvs {

namespace fs = std::filesystem;
using io_detail::ParseDouble;
using io_detail::RequireTokens;
using io_detail::Split;

namespace {

// Trailing number of a file stem, or -1.
long long TrailingNumber(const std::string& stem) {
  size_t e = stem.size();
  size_t b = e;
  while (b > 0 && std::isdigit(static_cast<unsigned char>(stem[b - 1]))) --b;
  if (b == e || e - b > 12) return -1;
  return std::stoll(stem.substr(b));
}

bool IsImageFile(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(c));
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" ||
         ext == ".tiff" || ext == ".bmp" || ext == ".ppm" || ext == ".pgm";
}

}  // namespace

Camera DecomposeProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P_in,
                                 const std::string& what) {
  Require(P_in.allFinite(), what, ": projection matrix is not finite");
  Eigen::Matrix<double, 3, 4> P = P_in;
  Eigen::Matrix3d M = P.leftCols<3>();
  const double det = M.determinant();
  Require(std::abs(det) > 1e-12 * std::pow(M.norm(), 3), what,
          ": projection matrix is degenerate (det of left 3x3 = ", det, ")");
  if (det < 0) {
    P = -P;
    M = -M;
  }
  // RQ via QR of the row-reversed transpose: M = K R.
  Eigen::Matrix3d J;
  J << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((J * M).transpose());
  const Eigen::Matrix3d Q = qr.householderQ();
  const Eigen::Matrix3d U = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K = J * U.transpose() * J;
  Eigen::Matrix3d R = J * Q.transpose();
  // Make K's diagonal positive (K D, D R with D = diag(+-1)).
  for (int i = 0; i < 3; ++i)
    if (K(i, i) < 0) {
      K.col(i) *= -1;
      R.row(i) *= -1;
    }
  const Eigen::Vector3d t = K.inverse() * P.col(3);
  const double s = K(2, 2);
  K /= s;
  Require(R.determinant() > 0, what, ": decomposition gave a reflection");
  Require(std::abs(K(0, 1)) <= 1e-3 * K(0, 0), what, ": K has skew ", K(0, 1),
          " (not supported)");
  Camera c;
  c.fx = K(0, 0);
  c.fy = K(1, 1);
  c.cx = K(0, 2) + 0.5;
  c.cy = K(1, 2) + 0.5;
  c.R = NearestRotation(R);
  c.t = t;
  return c;
}

Eigen::Matrix<double, 3, 4> ReadProjectionMatrix(const std::string& path) {
  io_detail::TextFile f(path);
  Eigen::Matrix<double, 3, 4> P;
  std::string line;
  for (int r = 0; r < 3; ++r) {
    if (!f.NextData(&line))
      throw Error(Msg(path, " line ", f.line() + 1,
                      ": truncated file: expected row ", r + 1, " of P"));
    const auto tok = Split(line);
    RequireTokens(tok, 4, true, f.Where(), "projection matrix row");
    for (int c = 0; c < 4; ++c)
      P(r, c) = ParseDouble(tok[c], f.Where(), "projection matrix entry");
  }
  return P;
}

Scene ReadProjectionMatrices(const std::string& cameras_dir,
                             const std::string& images_dir) {
  std::error_code ec;
  Require(fs::is_directory(cameras_dir, ec), cameras_dir,
          ": camera folder does not exist");
  Require(fs::is_directory(images_dir, ec), images_dir,
          ": image folder does not exist");
  std::map<long long, std::string> cams;
  for (const auto& e : fs::directory_iterator(cameras_dir, ec)) {
    if (e.path().extension() != ".projmatrix") continue;
    const long long n = TrailingNumber(e.path().stem().string());
    Require(n >= 0, e.path().string(), ": file name has no frame number");
    Require(cams.emplace(n, e.path().string()).second, e.path().string(),
            ": two camera files for frame ", n);
  }
  Require(!cams.empty(), cameras_dir, ": empty model: no *.projmatrix files");
  std::vector<std::string> images;
  for (auto it = fs::recursive_directory_iterator(images_dir, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    if (it->is_regular_file(ec) && IsImageFile(it->path()))
      images.push_back(fs::relative(it->path(), images_dir, ec).string());
  }
  std::sort(images.begin(), images.end());
  Scene scene;
  scene.source =
      Msg("projection matrices ", cameras_dir, " + images ", images_dir);
  std::map<long long, Camera> decomposed;
  for (const std::string& name : images) {
    const long long n = TrailingNumber(fs::path(name).stem().string());
    auto it = cams.find(n);
    if (n < 0 || it == cams.end()) continue;
    auto d = decomposed.find(n);
    if (d == decomposed.end())
      d = decomposed
              .emplace(n, DecomposeProjectionMatrix(
                              ReadProjectionMatrix(it->second), it->second))
              .first;
    View v;
    v.name = name;
    v.image_path = (fs::path(images_dir) / name).string();
    v.camera = d->second;
    const ImageSize size = ReadImageSize(v.image_path);
    v.camera.width = size.width;
    v.camera.height = size.height;
    v.camera.Validate(it->second);
    scene.views.push_back(std::move(v));
  }
  Require(!scene.views.empty(), images_dir,
          ": empty model: no image file matches a camera frame number in ",
          cameras_dir);
  scene.Validate();
  return scene;
}

}  // namespace wild_mvs
