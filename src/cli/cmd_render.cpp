// Copyright wild_mvs authors. `wild_mvs render`: a picture of a fused cloud
// or a mesh (offscreen, io/render.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/specs.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/ply.h"
#include "wild_mvs/io/preview.h"
#include "wild_mvs/io/render.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;

Eigen::Vector3d ParseVector(const Args& args, const std::string& flag) {
  const std::vector<std::string> items = SplitList(args.Get(flag));
  if (items.size() != 3) {
    throw UsageError(Msg("option --", flag, ": expected X,Y,Z (got '",
                         args.Get(flag), "')"));
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    try {
      v[i] = ParseDouble(items[i], "option --" + flag);
    } catch (const Error& e) {
      throw UsageError(e.what());
    }
  }
  return v;
}

// Mean "up" (camera -y) of the cameras of a reconstruct folder next to the
// model (MODEL_DIR/cameras/*.txt), or zero when there are none.
Eigen::Vector3d UpFromCameras(const std::string& model_path) {
  const fs::path dir = fs::path(model_path).parent_path() / "cameras";
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return up;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.path().extension() != ".txt") continue;
    try {
      const Camera c = ReadDepthMapCamera(e.path().string(), nullptr);
      up -= c.R.row(1).transpose();
    } catch (const Error&) {
      continue;  // not a camera file
    }
  }
  return up;
}

}  // namespace

int RunRender(const CommandArgs& argv) {
  const CommandSpec spec = RenderSpec();
  Args args(spec, argv);
  if (args.help()) {
    PrintCommandHelp(spec, nullptr, std::cout);
    return 0;
  }
  const std::string in = args.positional(0);
  const std::string png = args.positional(1);
  const Mesh mesh = ReadPlyMesh(in);
  Require(!mesh.vertices.empty(), in, ": no vertices to render");
  const bool as_mesh = !mesh.faces.empty() && !args.Has("points");

  RenderOptions opt;
  opt.point_size = args.GetDouble("point-size", 0);
  opt.shade_colors = args.Has("shade");
  opt.mesh_vertex_colors = args.Has("mesh-colors");
  opt.supersample = args.GetInt("supersample", opt.supersample, 1, 8);
  opt.max_splat_px = args.GetDouble("max-splat", opt.max_splat_px);
  try {
    opt.Check();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }

  const int width = args.GetInt("width", 800, 16, 8192);
  const double hfov = args.GetDouble("hfov", 40);
  if (!(hfov > 0 && hfov < 170)) {
    throw UsageError("option --hfov must be in (0, 170) degrees");
  }
  Camera camera;
  if (args.Has("camera")) {
    const Camera given = ReadDepthMapCamera(args.Get("camera"), nullptr);
    const int height = args.GetInt(
        "height",
        std::max(16, static_cast<int>(std::lround(static_cast<double>(width) *
                                                  given.height / given.width))),
        16, 8192);
    if (args.Has("fit")) {
      camera =
          FitCameraToPoints(mesh.vertices.xyz, given.R, width, height, hfov);
    } else {
      camera = given.Resized(width, height);
    }
  } else {
    const int height = args.GetInt("height", width * 3 / 4, 16, 8192);
    const Eigen::Vector3d up =
        args.Has("up") ? ParseVector(args, "up") : UpFromCameras(in);
    camera = FitCameraToPoints(mesh.vertices.xyz,
                               AutoViewRotation(mesh.vertices, up), width,
                               height, hfov);
  }
  if (args.Has("roll")) {
    // Turn the picture counter-clockwise about the optical axis.
    const double a = args.GetDouble("roll", 0) * M_PI / 180.0;
    Eigen::Matrix3d Q;
    Q << std::cos(a), std::sin(a), 0, -std::sin(a), std::cos(a), 0, 0, 0, 1;
    const Eigen::Vector3d C = camera.Center();
    camera.R = Q * camera.R;
    camera.t = -camera.R * C;
    if (camera.width != camera.height && std::abs(std::sin(a)) > 0.5 &&
        !args.Has("height")) {
      // Mostly sideways: swap the picture's sides, keeping the focal length.
      std::swap(camera.width, camera.height);
      std::swap(camera.fx, camera.fy);
      camera.cx = 0.5 * camera.width;
      camera.cy = 0.5 * camera.height;
    }
  }
  const cv::Mat image = as_mesh ? RenderMesh(mesh, camera, opt)
                                : RenderPointCloud(mesh.vertices, camera, opt);
  WriteImageAtomically(png, image, {cv::IMWRITE_PNG_COMPRESSION, 9});
  std::cout << "rendered " << (as_mesh ? "mesh" : "cloud") << " ("
            << mesh.vertices.size() << " vertices"
            << (as_mesh ? Msg(", ", mesh.faces.size(), " faces") : "")
            << ") at " << image.cols << "x" << image.rows << ": " << png
            << "\n";
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
