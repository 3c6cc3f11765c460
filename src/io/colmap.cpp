// Copyright wild_mvs authors.
#include "wild_mvs/io/colmap.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include "byte_reader.h"
#include "distortion_util.h"
#include "text_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;
using io_detail::ByteReader;
using io_detail::ParseDouble;
using io_detail::ParseInt;
using io_detail::RequireTokens;
using io_detail::Split;
using io_detail::TextFile;

struct ModelInfo {
  const char* name;
  int id;
  int num_params;
};
// COLMAP's camera model ids and parameter counts.
constexpr ModelInfo kModels[] = {{"SIMPLE_PINHOLE", 0, 3},
                                 {"PINHOLE", 1, 4},
                                 {"SIMPLE_RADIAL", 2, 4},
                                 {"RADIAL", 3, 5},
                                 {"OPENCV", 4, 8},
                                 {"OPENCV_FISHEYE", 5, 8},
                                 {"FULL_OPENCV", 6, 12},
                                 {"FOV", 7, 5},
                                 {"SIMPLE_RADIAL_FISHEYE", 8, 4},
                                 {"RADIAL_FISHEYE", 9, 5},
                                 {"THIN_PRISM_FISHEYE", 10, 12},
                                 {"RAD_TAN_THIN_PRISM_FISHEYE", 11, 16}};

const ModelInfo* ModelByName(const std::string& name) {
  for (const ModelInfo& m : kModels)
    if (name == m.name) return &m;
  return nullptr;
}
const ModelInfo* ModelById(int id) {
  for (const ModelInfo& m : kModels)
    if (id == m.id) return &m;
  return nullptr;
}

struct RawCamera {
  Camera camera;
  Distortion distortion;
};

struct RawImage {
  uint64_t id = 0;
  Eigen::Vector4d q{1, 0, 0, 0};  // w x y z
  Eigen::Vector3d t{0, 0, 0};
  uint64_t camera_id = 0;
  std::string name;
  std::vector<Eigen::Vector2d> points2d;
  std::string where;
};

struct RawPoint {
  uint64_t id = 0;
  Eigen::Vector3d xyz{0, 0, 0};
  Eigen::Vector3f rgb{0, 0, 0};
  double error = 0;
  std::vector<std::pair<uint64_t, uint64_t>> track;  // image id, point2D idx
  std::string where;
};

// Builds the pinhole camera + distortion of a COLMAP camera; `where` names
// the file and line / offset for errors.
RawCamera MakeCamera(const std::string& model_name, int num_params_found,
                     const double* p, long long width, long long height,
                     const std::string& where) {
  const ModelInfo* m = ModelByName(model_name);
  if (!m) throw Error(Msg(where, ": unknown camera model '", model_name, "'"));
  const std::string mn = model_name;
  if (mn.find("FISHEYE") != std::string::npos || mn == "FOV")
    throw Error(Msg(where, ": fisheye camera model ", mn,
                    " is not supported (undistort the images first, e.g. with "
                    "colmap image_undistorter)"));
  if (m->id > 4)
    throw Error(Msg(where, ": camera model ", mn,
                    " is not supported (supported: SIMPLE_PINHOLE, PINHOLE, "
                    "SIMPLE_RADIAL, RADIAL, OPENCV)"));
  if (num_params_found < m->num_params)
    throw Error(Msg(where, ": truncated line: camera model ", mn, " needs ",
                    m->num_params, " parameters, found ", num_params_found));
  if (num_params_found > m->num_params)
    throw Error(Msg(where, ": camera model ", mn, " needs ", m->num_params,
                    " parameters, found ", num_params_found));
  Require(width > 0 && height > 0 && width <= 1000000 && height <= 1000000,
          where, ": invalid image size ", width, "x", height);
  RawCamera rc;
  Camera& c = rc.camera;
  c.width = static_cast<int>(width);
  c.height = static_cast<int>(height);
  Distortion& d = rc.distortion;
  switch (m->id) {
    case 0:  // SIMPLE_PINHOLE f cx cy
    case 2:  // SIMPLE_RADIAL f cx cy k
    case 3:  // RADIAL f cx cy k1 k2
      c.fx = c.fy = p[0];
      c.cx = p[1];
      c.cy = p[2];
      if (m->id >= 2) {
        d.model = Distortion::Model::kRadial;
        d.k1 = p[3];
        if (m->id == 3) d.k2 = p[4];
      }
      break;
    case 1:  // PINHOLE fx fy cx cy
    case 4:  // OPENCV fx fy cx cy k1 k2 p1 p2
      c.fx = p[0];
      c.fy = p[1];
      c.cx = p[2];
      c.cy = p[3];
      if (m->id == 4) {
        d.model = Distortion::Model::kOpenCV;
        d.k1 = p[4];
        d.k2 = p[5];
        d.p1 = p[6];
        d.p2 = p[7];
      }
      break;
  }
  for (int i = 0; i < m->num_params; ++i)
    Require(std::isfinite(p[i]), where, ": camera parameter ", i,
            " is not finite");
  Require(c.fx > 0 && c.fy > 0, where,
          ": focal length must be positive (fx=", c.fx, " fy=", c.fy, ")");
  if (d.IsNone()) d.model = Distortion::Model::kNone;
  return rc;
}

Eigen::Matrix3d RotationFromQuaternion(const Eigen::Vector4d& q,
                                       const std::string& where) {
  Require(q.allFinite(), where, ": quaternion is not finite");
  const double n = q.norm();
  Require(std::abs(n - 1.0) < 1e-3, where, ": quaternion (", q.transpose(),
          ") has norm ", n, ", expected 1: not a rotation");
  return Eigen::Quaterniond(q[0] / n, q[1] / n, q[2] / n, q[3] / n)
      .toRotationMatrix();
}

Scene Assemble(const std::map<uint64_t, RawCamera>& cameras,
               const std::string& cameras_file,
               const std::vector<RawImage>& images,
               const std::string& images_file,
               const std::vector<RawPoint>& points,
               const std::string& images_dir, const std::string& source) {
  Require(!cameras.empty(), cameras_file, ": empty model: no cameras");
  Require(!images.empty(), images_file, ": empty model: no images");
  Scene scene;
  scene.source = source;
  std::unordered_map<uint64_t, int> view_of_image;
  std::unordered_set<std::string> names;
  std::vector<std::vector<Eigen::Vector2d>> undistorted;
  for (const RawImage& im : images) {
    Require(view_of_image.emplace(im.id, static_cast<int>(scene.views.size()))
                .second,
            im.where, ": duplicate IMAGE_ID ", im.id);
    Require(!im.name.empty(), im.where, ": empty image name");
    Require(names.insert(im.name).second, im.where, ": duplicate image name '",
            im.name, "'");
    auto cam = cameras.find(im.camera_id);
    Require(cam != cameras.end(), im.where, ": image '", im.name,
            "' refers to CAMERA_ID ", im.camera_id, " which is not in ",
            cameras_file);
    View v;
    v.name = im.name;
    if (!images_dir.empty())
      v.image_path = (fs::path(images_dir) / im.name).string();
    v.camera = cam->second.camera;
    v.distortion = cam->second.distortion;
    v.camera.R = RotationFromQuaternion(im.q, im.where);
    Require(im.t.allFinite(), im.where, ": translation is not finite");
    v.camera.t = im.t;
    v.camera.Validate(im.where);
    std::vector<Eigen::Vector2d> pts = im.points2d;
    io_detail::UndistortPixels(v.camera, v.distortion, &pts);
    undistorted.push_back(std::move(pts));
    scene.views.push_back(std::move(v));
  }
  std::unordered_set<uint64_t> point_ids;
  scene.points.reserve(points.size());
  for (const RawPoint& rp : points) {
    Require(point_ids.insert(rp.id).second, rp.where, ": duplicate POINT3D_ID ",
            rp.id);
    SparsePoint sp;
    sp.xyz = rp.xyz;
    sp.rgb = rp.rgb;
    sp.error = rp.error;
    sp.track.reserve(rp.track.size());
    for (const auto& [image_id, idx] : rp.track) {
      auto it = view_of_image.find(image_id);
      Require(it != view_of_image.end(), rp.where, ": point ", rp.id,
              " has a track entry for IMAGE_ID ", image_id, " which is not in ",
              images_file);
      const auto& pts = undistorted[it->second];
      Require(idx < pts.size(), rp.where, ": point ", rp.id,
              " refers to POINT2D_IDX ", idx, " of image '",
              scene.views[it->second].name, "' which has only ", pts.size(),
              " 2D points");
      Observation o;
      o.view = it->second;
      o.xy = pts[idx];
      sp.track.push_back(o);
    }
    scene.points.push_back(std::move(sp));
  }
  scene.Validate();
  return scene;
}

// ---------------------------------------------------------------- text
std::map<uint64_t, RawCamera> ReadCamerasText(const std::string& path) {
  TextFile f(path);
  std::map<uint64_t, RawCamera> cameras;
  std::string line;
  while (f.NextData(&line)) {
    const std::string w = f.Where();
    const auto tok = Split(line);
    RequireTokens(tok, 4, false, w,
                  "camera (CAMERA_ID MODEL WIDTH HEIGHT PARAMS)");
    const long long id = ParseInt(tok[0], w, "CAMERA_ID");
    Require(id >= 0, w, ": negative CAMERA_ID ", id);
    const long long width = ParseInt(tok[2], w, "WIDTH");
    const long long height = ParseInt(tok[3], w, "HEIGHT");
    std::vector<double> params;
    for (size_t i = 4; i < tok.size(); ++i)
      params.push_back(ParseDouble(tok[i], w, "camera parameter"));
    params.resize(std::max<size_t>(params.size(), 16), 0.0);
    RawCamera rc = MakeCamera(tok[1], static_cast<int>(tok.size()) - 4,
                              params.data(), width, height, w);
    Require(cameras.emplace(static_cast<uint64_t>(id), rc).second, w,
            ": duplicate CAMERA_ID ", id);
  }
  return cameras;
}

std::vector<RawImage> ReadImagesText(const std::string& path) {
  TextFile f(path);
  std::vector<RawImage> images;
  std::string line;
  while (f.NextData(&line)) {
    RawImage im;
    im.where = f.Where();
    const auto tok = Split(line);
    RequireTokens(tok, 10, false, im.where,
                  "image (IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME)");
    const long long id = ParseInt(tok[0], im.where, "IMAGE_ID");
    Require(id >= 0, im.where, ": negative IMAGE_ID ", id);
    im.id = static_cast<uint64_t>(id);
    for (int i = 0; i < 4; ++i)
      im.q[i] = ParseDouble(tok[1 + i], im.where, "quaternion");
    for (int i = 0; i < 3; ++i)
      im.t[i] = ParseDouble(tok[5 + i], im.where, "translation");
    const long long cid = ParseInt(tok[8], im.where, "CAMERA_ID");
    Require(cid >= 0, im.where, ": negative CAMERA_ID ", cid);
    im.camera_id = static_cast<uint64_t>(cid);
    im.name = tok[9];
    for (size_t i = 10; i < tok.size(); ++i) im.name += " " + tok[i];
    // The POINTS2D line follows directly (it may be empty).
    std::string pl;
    if (f.Next(&pl)) {
      const std::string pw = f.Where();
      const auto pt = Split(pl);
      Require(pt.size() % 3 == 0, pw, ": truncated POINTS2D line: ", pt.size(),
              " values is not a multiple of 3 (X Y POINT3D_ID)");
      im.points2d.reserve(pt.size() / 3);
      for (size_t i = 0; i < pt.size(); i += 3) {
        im.points2d.emplace_back(ParseDouble(pt[i], pw, "2D point X"),
                                 ParseDouble(pt[i + 1], pw, "2D point Y"));
        ParseInt(pt[i + 2], pw, "POINT3D_ID");
      }
    }
    images.push_back(std::move(im));
  }
  return images;
}

std::vector<RawPoint> ReadPointsText(const std::string& path) {
  std::vector<RawPoint> points;
  if (!fs::exists(path)) return points;
  TextFile f(path);
  std::string line;
  while (f.NextData(&line)) {
    RawPoint p;
    p.where = f.Where();
    const auto tok = Split(line);
    RequireTokens(tok, 8, false, p.where,
                  "point (POINT3D_ID X Y Z R G B ERROR TRACK[])");
    const long long id = ParseInt(tok[0], p.where, "POINT3D_ID");
    Require(id >= 0, p.where, ": negative POINT3D_ID ", id);
    p.id = static_cast<uint64_t>(id);
    for (int i = 0; i < 3; ++i)
      p.xyz[i] = ParseDouble(tok[1 + i], p.where, "coordinate");
    for (int i = 0; i < 3; ++i) {
      const long long c = ParseInt(tok[4 + i], p.where, "colour");
      Require(c >= 0 && c <= 255, p.where, ": colour ", c,
              " is outside 0..255");
      p.rgb[i] = static_cast<float>(c / 255.0);
    }
    p.error = ParseDouble(tok[7], p.where, "ERROR");
    Require((tok.size() - 8) % 2 == 0, p.where,
            ": truncated track: odd number of values (IMAGE_ID POINT2D_IDX "
            "pairs expected)");
    for (size_t i = 8; i < tok.size(); i += 2) {
      const long long img = ParseInt(tok[i], p.where, "IMAGE_ID");
      const long long idx = ParseInt(tok[i + 1], p.where, "POINT2D_IDX");
      Require(img >= 0 && idx >= 0, p.where, ": negative track entry ", img,
              " ", idx);
      p.track.emplace_back(img, idx);
    }
    points.push_back(std::move(p));
  }
  return points;
}

// ---------------------------------------------------------------- binary
std::string Where(const ByteReader& r, const std::string& what) {
  return Msg(r.path(), " byte ", r.offset(), " (", what, ")");
}

std::map<uint64_t, RawCamera> ReadCamerasBinary(const std::string& path) {
  const std::string data = io_detail::ReadWholeFile(path);
  ByteReader r(data, path);
  const uint64_t n = r.Read<uint64_t>("number of cameras");
  r.RequireCount(n, 4 + 4 + 8 + 8 + 3 * 8, "number of cameras");
  std::map<uint64_t, RawCamera> cameras;
  for (uint64_t i = 0; i < n; ++i) {
    const std::string w = Where(r, Msg("camera ", i));
    const uint32_t id = r.Read<uint32_t>("CAMERA_ID");
    const int32_t model = r.Read<int32_t>("model id");
    const uint64_t width = r.Read<uint64_t>("width");
    const uint64_t height = r.Read<uint64_t>("height");
    const ModelInfo* m = ModelById(model);
    if (!m) throw Error(Msg(w, ": unknown camera model id ", model));
    double params[16] = {0};
    for (int k = 0; k < m->num_params; ++k)
      params[k] = r.Read<double>("camera parameter");
    Require(width <= 1000000 && height <= 1000000, w, ": invalid image size ",
            width, "x", height);
    RawCamera rc = MakeCamera(m->name, m->num_params, params,
                              static_cast<long long>(width),
                              static_cast<long long>(height), w);
    Require(cameras.emplace(id, rc).second, w, ": duplicate CAMERA_ID ", id);
  }
  Require(r.AtEnd(), path, ": corrupt file: ", r.remaining(),
          " unexpected bytes after the last camera");
  return cameras;
}

std::vector<RawImage> ReadImagesBinary(const std::string& path) {
  const std::string data = io_detail::ReadWholeFile(path);
  ByteReader r(data, path);
  const uint64_t n = r.Read<uint64_t>("number of images");
  r.RequireCount(n, 4 + 7 * 8 + 4 + 1 + 8, "number of images");
  std::vector<RawImage> images;
  images.reserve(n);
  for (uint64_t i = 0; i < n; ++i) {
    RawImage im;
    im.where = Where(r, Msg("image ", i));
    im.id = r.Read<uint32_t>("IMAGE_ID");
    for (int k = 0; k < 4; ++k) im.q[k] = r.Read<double>("quaternion");
    for (int k = 0; k < 3; ++k) im.t[k] = r.Read<double>("translation");
    im.camera_id = r.Read<uint32_t>("CAMERA_ID");
    im.name = r.ReadCString("image name");
    const uint64_t np = r.Read<uint64_t>("number of 2D points");
    r.RequireCount(np, 24, "number of 2D points");
    im.points2d.reserve(np);
    for (uint64_t k = 0; k < np; ++k) {
      const double x = r.Read<double>("2D point X");
      const double y = r.Read<double>("2D point Y");
      r.Read<uint64_t>("POINT3D_ID");
      Require(std::isfinite(x) && std::isfinite(y), im.where, ": 2D point ", k,
              " is not finite");
      im.points2d.emplace_back(x, y);
    }
    images.push_back(std::move(im));
  }
  Require(r.AtEnd(), path, ": corrupt file: ", r.remaining(),
          " unexpected bytes after the last image");
  return images;
}

std::vector<RawPoint> ReadPointsBinary(const std::string& path) {
  std::vector<RawPoint> points;
  if (!fs::exists(path)) return points;
  const std::string data = io_detail::ReadWholeFile(path);
  ByteReader r(data, path);
  const uint64_t n = r.Read<uint64_t>("number of points");
  r.RequireCount(n, 8 + 24 + 3 + 8 + 8, "number of points");
  points.reserve(n);
  for (uint64_t i = 0; i < n; ++i) {
    RawPoint p;
    p.where = Where(r, Msg("point ", i));
    p.id = r.Read<uint64_t>("POINT3D_ID");
    for (int k = 0; k < 3; ++k) p.xyz[k] = r.Read<double>("coordinate");
    for (int k = 0; k < 3; ++k)
      p.rgb[k] = static_cast<float>(r.Read<uint8_t>("colour") / 255.0);
    p.error = r.Read<double>("ERROR");
    Require(p.xyz.allFinite() && std::isfinite(p.error), p.where,
            ": point is not finite");
    const uint64_t len = r.Read<uint64_t>("track length");
    r.RequireCount(len, 8, "track length");
    p.track.reserve(len);
    for (uint64_t k = 0; k < len; ++k) {
      const uint32_t img = r.Read<uint32_t>("IMAGE_ID");
      const uint32_t idx = r.Read<uint32_t>("POINT2D_IDX");
      p.track.emplace_back(img, idx);
    }
    points.push_back(std::move(p));
  }
  Require(r.AtEnd(), path, ": corrupt file: ", r.remaining(),
          " unexpected bytes after the last point");
  return points;
}

bool Exists(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

}  // namespace

ColmapFormat DetectColmapModel(const std::string& dir) {
  const fs::path d(dir);
  if (Exists(d / "cameras.txt") && Exists(d / "images.txt"))
    return ColmapFormat::kText;
  if (Exists(d / "cameras.bin") && Exists(d / "images.bin"))
    return ColmapFormat::kBinary;
  return ColmapFormat::kNone;
}

Scene ReadColmapModel(const std::string& model_dir,
                      const std::string& images_dir) {
  switch (DetectColmapModel(model_dir)) {
    case ColmapFormat::kText:
      return ReadColmapText(model_dir, images_dir);
    case ColmapFormat::kBinary:
      return ReadColmapBinary(model_dir, images_dir);
    default:
      throw Error(Msg(model_dir,
                      ": no COLMAP model here (expected cameras.txt + "
                      "images.txt [+ points3D.txt] or the .bin files)"));
  }
}

Scene ReadColmapText(const std::string& model_dir,
                     const std::string& images_dir) {
  const fs::path d(model_dir);
  const std::string cf = (d / "cameras.txt").string();
  const std::string imf = (d / "images.txt").string();
  const std::string pf = (d / "points3D.txt").string();
  const auto cameras = ReadCamerasText(cf);
  const auto images = ReadImagesText(imf);
  const auto points = ReadPointsText(pf);
  std::string source = Msg("COLMAP text model ", model_dir);
  if (!Exists(pf)) source += " (no points3D.txt)";
  return Assemble(cameras, cf, images, imf, points, images_dir, source);
}

Scene ReadColmapBinary(const std::string& model_dir,
                       const std::string& images_dir) {
  const fs::path d(model_dir);
  const std::string cf = (d / "cameras.bin").string();
  const std::string imf = (d / "images.bin").string();
  const std::string pf = (d / "points3D.bin").string();
  const auto cameras = ReadCamerasBinary(cf);
  const auto images = ReadImagesBinary(imf);
  const auto points = ReadPointsBinary(pf);
  std::string source = Msg("COLMAP binary model ", model_dir);
  if (!Exists(pf)) source += " (no points3D.bin)";
  return Assemble(cameras, cf, images, imf, points, images_dir, source);
}

void WriteColmapText(const Scene& scene, const std::string& dir) {
  const fs::path d(dir);
  const size_t nv = scene.views.size();
  // Per view: file-resolution camera and scale from camera pixels.
  std::vector<Camera> cams(nv);
  std::vector<Eigen::Vector2d> scale(nv, Eigen::Vector2d(1, 1));
  for (size_t i = 0; i < nv; ++i) {
    const View& v = scene.views[i];
    cams[i] = v.camera;
    if (v.file_width > 0 && v.file_height > 0 &&
        (v.file_width != v.camera.width || v.file_height != v.camera.height)) {
      cams[i] = v.camera.Resized(v.file_width, v.file_height);
      scale[i] = Eigen::Vector2d(double(v.file_width) / v.camera.width,
                                 double(v.file_height) / v.camera.height);
    }
  }
  // 2D points per view: (pixel in the file, point id); track indices.
  std::vector<std::vector<std::pair<Eigen::Vector2d, size_t>>> obs(nv);
  std::vector<std::vector<std::pair<size_t, size_t>>> tracks(
      scene.points.size());
  for (size_t p = 0; p < scene.points.size(); ++p) {
    for (const Observation& o : scene.points[p].track) {
      Require(o.view >= 0 && o.view < static_cast<int>(nv), "WriteColmapText ",
              dir, ": point ", p, " has a track entry for missing view ",
              o.view);
      const Eigen::Vector2d xy = o.xy.cwiseProduct(scale[o.view]);
      const Eigen::Vector2d px = io_detail::DistortPixel(
          cams[o.view], scene.views[o.view].distortion, xy);
      tracks[p].emplace_back(o.view + 1, obs[o.view].size());
      obs[o.view].emplace_back(px, p + 1);
    }
  }
  const int prec = std::numeric_limits<double>::max_digits10;
  WriteFileAtomically((d / "cameras.txt").string(), [&](std::ostream& os) {
    os << "# Camera list with one line of data per camera:\n"
          "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
          "# Number of cameras: "
       << nv << "\n"
       << std::setprecision(prec);
    for (size_t i = 0; i < nv; ++i) {
      const Camera& c = cams[i];
      const Distortion& dd = scene.views[i].distortion;
      if (dd.IsNone()) {
        os << i + 1 << " PINHOLE " << c.width << " " << c.height << " " << c.fx
           << " " << c.fy << " " << c.cx << " " << c.cy << "\n";
      } else {
        Require(dd.k3 == 0, "WriteColmapText ", dir, ": view '",
                scene.views[i].name,
                "' has k3 != 0, which COLMAP's OPENCV model cannot store");
        os << i + 1 << " OPENCV " << c.width << " " << c.height << " " << c.fx
           << " " << c.fy << " " << c.cx << " " << c.cy << " " << dd.k1 << " "
           << dd.k2 << " " << dd.p1 << " " << dd.p2 << "\n";
      }
    }
  });
  WriteFileAtomically((d / "images.txt").string(), [&](std::ostream& os) {
    os << "# Image list with two lines of data per image:\n"
          "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
          "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
          "# Number of images: "
       << nv << "\n"
       << std::setprecision(prec);
    for (size_t i = 0; i < nv; ++i) {
      const Camera& c = scene.views[i].camera;
      Eigen::Quaterniond q(c.R);
      q.normalize();
      if (q.w() < 0) q.coeffs() *= -1;
      os << i + 1 << " " << q.w() << " " << q.x() << " " << q.y() << " "
         << q.z() << " " << c.t.x() << " " << c.t.y() << " " << c.t.z() << " "
         << i + 1 << " " << scene.views[i].name << "\n";
      bool first = true;
      for (const auto& [px, pid] : obs[i]) {
        os << (first ? "" : " ") << px.x() << " " << px.y() << " " << pid;
        first = false;
      }
      os << "\n";
    }
  });
  WriteFileAtomically((d / "points3D.txt").string(), [&](std::ostream& os) {
    os << "# 3D point list with one line of data per point:\n"
          "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, "
          "POINT2D_IDX)\n"
          "# Number of points: "
       << scene.points.size() << "\n"
       << std::setprecision(prec);
    for (size_t p = 0; p < scene.points.size(); ++p) {
      const SparsePoint& sp = scene.points[p];
      os << p + 1 << " " << sp.xyz.x() << " " << sp.xyz.y() << " "
         << sp.xyz.z();
      for (int k = 0; k < 3; ++k)
        os << " "
           << static_cast<int>(
                  std::lround(std::clamp(sp.rgb[k], 0.0f, 1.0f) * 255.0f));
      os << " " << sp.error;
      for (const auto& [img, idx] : tracks[p]) os << " " << img << " " << idx;
      os << "\n";
    }
  });
}

}  // namespace wild_mvs
