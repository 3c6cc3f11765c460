// Copyright wild_mvs authors.
#include "wild_mvs/io/middlebury.h"

#include <cmath>
#include <filesystem>
#include <unordered_set>

#include "text_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/image_size.h"

namespace wild_mvs {

namespace fs = std::filesystem;
using io_detail::ParseDouble;
using io_detail::ParseInt;
using io_detail::RequireTokens;
using io_detail::Split;
using io_detail::TextFile;

Scene ReadMiddleburyPar(const std::string& par_file,
                        const std::string& images_dir_in) {
  const std::string images_dir = images_dir_in.empty()
                                     ? fs::path(par_file).parent_path().string()
                                     : images_dir_in;
  TextFile f(par_file);
  std::string line;
  if (!f.NextData(&line))
    throw Error(Msg(par_file, ": empty model: no image count"));
  auto tok = Split(line);
  RequireTokens(tok, 1, true, f.Where(), "image count");
  const long long n = ParseInt(tok[0], f.Where(), "image count");
  Require(n > 0 && n < 10000000, f.Where(), ": invalid image count ", n,
          n == 0 ? " (empty model)" : "");
  Scene scene;
  scene.source = Msg("Middlebury cameras ", par_file);
  std::unordered_set<std::string> names;
  for (long long i = 0; i < n; ++i) {
    if (!f.NextData(&line))
      throw Error(Msg(par_file, " line ", f.line() + 1,
                      ": truncated file: expected ", n, " images, found ", i));
    const std::string w = f.Where();
    tok = Split(line);
    RequireTokens(tok, 22, true, w, "camera (name k11..k33 r11..r33 t1 t2 t3)");
    double v[21];
    for (int k = 0; k < 21; ++k)
      v[k] = ParseDouble(tok[1 + k], w,
                         k < 9    ? "K entry"
                         : k < 18 ? "R entry"
                                  : "t entry");
    View view;
    view.name = tok[0];
    Require(names.insert(view.name).second, w, ": duplicate image name '",
            view.name, "'");
    Eigen::Matrix3d K, R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        K(r, c) = v[3 * r + c];
        R(r, c) = v[9 + 3 * r + c];
      }
    Require(K(2, 2) != 0, w, ": K33 must be non-zero");
    K /= K(2, 2);
    Require(std::abs(K(2, 0)) < 1e-9 && std::abs(K(2, 1)) < 1e-9 &&
                std::abs(K(1, 0)) < 1e-9,
            w, ": K is not upper triangular with last row (0 0 1)");
    Require(K(0, 0) > 0 && K(1, 1) > 0, w,
            ": focal length must be positive (fx=", K(0, 0), " fy=", K(1, 1),
            ")");
    Require(std::abs(K(0, 1)) <= 1e-6 * K(0, 0), w, ": K has skew ", K(0, 1),
            " (not supported)");
    const double orth =
        (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
    Require(orth < 1e-3 && R.determinant() > 0, w,
            ": rotation is not orthonormal (|R R^T - I| = ", orth,
            ", det = ", R.determinant(), ")");
    view.image_path = (fs::path(images_dir) / view.name).string();
    const ImageSize size = ReadImageSize(view.image_path);
    Camera& c = view.camera;
    c.width = size.width;
    c.height = size.height;
    c.fx = K(0, 0);
    c.fy = K(1, 1);
    c.cx = K(0, 2) + 0.5;
    c.cy = K(1, 2) + 0.5;
    c.R = NearestRotation(R);
    c.t = Eigen::Vector3d(v[18], v[19], v[20]);
    c.Validate(w);
    scene.views.push_back(std::move(view));
  }
  scene.Validate();
  return scene;
}

}  // namespace wild_mvs
