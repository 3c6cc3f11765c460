// Copyright wild_mvs authors.
#include "wild_mvs/io/bundler.h"

#include <filesystem>

#include "distortion_util.h"
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

namespace {

std::vector<std::string> ReadList(const std::string& list_file) {
  TextFile f(list_file);
  std::vector<std::string> names;
  std::string line;
  while (f.Next(&line)) {
    const auto tok = Split(line);
    if (tok.empty()) continue;
    std::string name = tok[0];
    while (name.rfind("./", 0) == 0) name = name.substr(2);
    Require(!name.empty(), f.Where(), ": empty image name");
    names.push_back(name);
  }
  return names;
}

}  // namespace

Scene ReadBundler(const std::string& bundle_file, const std::string& list_file,
                  const std::string& image_root_in) {
  const std::string image_root =
      image_root_in.empty() ? fs::path(list_file).parent_path().string()
                            : image_root_in;
  const std::vector<std::string> names = ReadList(list_file);
  TextFile f(bundle_file);
  std::string line;
  auto next = [&](const char* what) {
    if (!f.NextData(&line))
      throw Error(Msg(bundle_file, " line ", f.line() + 1,
                      ": truncated file: expected ", what));
    return Split(line);
  };
  auto tok = next("\"num_cameras num_points\"");
  RequireTokens(tok, 2, true, f.Where(), "header (num_cameras num_points)");
  const long long nc = ParseInt(tok[0], f.Where(), "number of cameras");
  const long long np = ParseInt(tok[1], f.Where(), "number of points");
  Require(nc > 0, f.Where(), ": empty model: ", nc, " cameras");
  Require(np >= 0 && np < 1000000000LL, f.Where(),
          ": invalid number of points ", np);
  Require(static_cast<size_t>(nc) == names.size(), f.Where(), ": ", nc,
          " cameras but ", list_file, " lists ", names.size(), " images");

  Scene scene;
  std::vector<int> view_of_camera(nc, -1);
  std::vector<std::string> skipped;
  for (long long i = 0; i < nc; ++i) {
    tok = next("camera \"f k1 k2\"");
    const std::string w = f.Where();
    RequireTokens(tok, 3, true, w, "camera intrinsics (f k1 k2)");
    const double fl = ParseDouble(tok[0], w, "focal length");
    const double k1 = ParseDouble(tok[1], w, "k1");
    const double k2 = ParseDouble(tok[2], w, "k2");
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      tok = next("camera rotation row");
      RequireTokens(tok, 3, true, f.Where(), "rotation row");
      for (int k = 0; k < 3; ++k)
        R(r, k) = ParseDouble(tok[k], f.Where(), "rotation");
    }
    const std::string rot_where =
        Msg(bundle_file, " lines ", f.line() - 2, "-", f.line());
    tok = next("camera translation");
    RequireTokens(tok, 3, true, f.Where(), "translation");
    Eigen::Vector3d t;
    for (int k = 0; k < 3; ++k)
      t[k] = ParseDouble(tok[k], f.Where(), "translation");
    if (fl == 0) {  // not registered by Bundler
      skipped.push_back(names[i]);
      continue;
    }
    Require(fl > 0, w, ": focal length must be positive (f=", fl, ")");
    const double orth =
        (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
    Require(orth < 1e-3 && R.determinant() > 0, rot_where,
            ": rotation is not orthonormal (|R R^T - I| = ", orth,
            ", det = ", R.determinant(), ")");
    View v;
    v.name = names[i];
    v.image_path = (fs::path(image_root) / v.name).string();
    const ImageSize size = ReadImageSize(v.image_path);
    Camera& c = v.camera;
    c.width = size.width;
    c.height = size.height;
    c.fx = c.fy = fl;
    c.cx = 0.5 * size.width;
    c.cy = 0.5 * size.height;
    const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
    c.R = NearestRotation(flip * R);
    c.t = flip * t;
    if (k1 != 0 || k2 != 0) {
      v.distortion.model = Distortion::Model::kRadial;
      v.distortion.k1 = k1;
      v.distortion.k2 = k2;
    }
    c.Validate(w);
    view_of_camera[i] = static_cast<int>(scene.views.size());
    scene.views.push_back(std::move(v));
  }
  Require(!scene.views.empty(), bundle_file,
          ": empty model: no registered camera (all have f = 0)");

  // Points: position, colour, view list.
  std::vector<std::vector<std::pair<int, Eigen::Vector2d>>> per_view(
      scene.views.size());  // (point index, raw pixel) for undistortion
  size_t dropped_obs = 0, dropped_points = 0;
  for (long long p = 0; p < np; ++p) {
    SparsePoint sp;
    tok = next("point position");
    RequireTokens(tok, 3, true, f.Where(), "point position");
    for (int k = 0; k < 3; ++k)
      sp.xyz[k] = ParseDouble(tok[k], f.Where(), "point coordinate");
    tok = next("point colour");
    RequireTokens(tok, 3, true, f.Where(), "point colour");
    for (int k = 0; k < 3; ++k) {
      const long long c = ParseInt(tok[k], f.Where(), "colour");
      Require(c >= 0 && c <= 255, f.Where(), ": colour ", c,
              " is outside 0..255");
      sp.rgb[k] = static_cast<float>(c / 255.0);
    }
    tok = next("point view list");
    const std::string w = f.Where();
    RequireTokens(tok, 1, false, w, "view list");
    const long long n = ParseInt(tok[0], w, "view list length");
    Require(n >= 0 && n <= nc, w, ": invalid view list length ", n);
    RequireTokens(tok, 1 + 4 * static_cast<size_t>(n), true, w,
                  "view list (n, then n x \"camera key x y\")");
    for (long long k = 0; k < n; ++k) {
      const long long cam = ParseInt(tok[1 + 4 * k], w, "camera index");
      ParseInt(tok[2 + 4 * k], w, "key index");
      const double x = ParseDouble(tok[3 + 4 * k], w, "x");
      const double y = ParseDouble(tok[4 + 4 * k], w, "y");
      Require(cam >= 0 && cam < nc, w, ": view list refers to camera ", cam,
              " but there are ", nc, " cameras");
      const int v = view_of_camera[cam];
      if (v < 0) {
        ++dropped_obs;
        continue;
      }
      const Camera& c = scene.views[v].camera;
      Observation o;
      o.view = v;
      o.xy = Eigen::Vector2d(x + 0.5 * c.width, 0.5 * c.height - y);
      per_view[v].emplace_back(static_cast<int>(scene.points.size()), o.xy);
      sp.track.push_back(o);
    }
    if (sp.track.empty()) {
      ++dropped_points;  // seen only by unregistered cameras
      continue;
    }
    scene.points.push_back(std::move(sp));
  }
  // Undistort observations per view.
  for (size_t v = 0; v < scene.views.size(); ++v) {
    if (scene.views[v].distortion.IsNone() || per_view[v].empty()) continue;
    std::vector<Eigen::Vector2d> px;
    for (const auto& e : per_view[v]) px.push_back(e.second);
    io_detail::UndistortPixels(scene.views[v].camera, scene.views[v].distortion,
                               &px);
    // Tracks list views in file order; find the entry of view v.
    for (size_t k = 0; k < px.size(); ++k)
      for (Observation& o : scene.points[per_view[v][k].first].track)
        if (o.view == static_cast<int>(v) && o.xy == per_view[v][k].second) {
          o.xy = px[k];
          break;
        }
  }
  scene.source = Msg("Bundler model ", bundle_file, " + ", list_file);
  if (!skipped.empty()) {
    scene.source +=
        Msg(" (", skipped.size(), " unregistered cameras with f = 0 skipped:");
    for (const std::string& s : skipped) scene.source += " " + s;
    scene.source += Msg("; ", dropped_obs, " observations and ", dropped_points,
                        " points dropped)");
  }
  scene.Validate();
  return scene;
}

}  // namespace wild_mvs
