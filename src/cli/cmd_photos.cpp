// Copyright wild_mvs authors. `wild_mvs photos PHOTO_DIR OUT`: a folder of
// photos (no poses) to a dense cloud and a mesh. COLMAP (Debian's colmap,
// run on the CPU as a subprocess) finds the cameras: feature_extractor,
// exhaustive_matcher (or sequential_matcher for many photos), mapper,
// image_undistorter into OUT/dense (a COLMAP dense workspace); then
// `wild_mvs reconstruct OUT/dense OUT` computes the depth maps, the cloud
// and the mesh and writes its maps into OUT/dense as COLMAP's own dense
// step would.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/option_command.h"
#include "wild_mvs/cli/subprocess.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/colmap_dense.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;

// Up to this many photos every pair is matched; beyond, neighbours in file
// name order (COLMAP's sequential matcher).
constexpr int kMaxExhaustivePhotos = 50;
// A photo joins the model with at least this many inlier matches to its
// points, and this fraction of its matches inliers (COLMAP's defaults are 30
// and 0.25; with them a ring of 16 photos around an object, 22.5 degrees
// apart, splits into two models and loses 3 photos).
const char* const kMinPoseInliers = "15";
const char* const kMinPoseInlierRatio = "0.15";
// The working size when neither --max-image-size nor the config sets one.
constexpr int kDefaultMaxImageSize = 1600;

CommandSpec PhotosSpec() {
  CommandSpec s;
  s.name = "photos";
  s.usage = "PHOTO_DIR OUT [options]";
  s.summary =
      "From a folder of photos (any sizes; no poses needed) to a dense\n"
      "cloud and a mesh. COLMAP finds the cameras on the CPU (colmap\n"
      "feature_extractor, exhaustive_matcher or, above 50 photos,\n"
      "sequential_matcher, mapper, image_undistorter; EXIF focal lengths are\n"
      "used where present), then 'wild_mvs reconstruct OUT/dense OUT' runs.\n"
      "OUT/fused.ply, OUT/mesh.ply and the per-view maps as 'reconstruct'\n"
      "writes them; OUT/colmap: COLMAP's database, sparse models and logs;\n"
      "OUT/dense: COLMAP's dense workspace (undistorted images, the model,\n"
      "and stereo/depth_maps, stereo/normal_maps, fused.ply(.vis) in\n"
      "COLMAP's formats, for colmap stereo_fusion, poisson_mesher and,\n"
      "when colmap is built with CGAL, delaunay_mesher). Needs the colmap\n"
      "program (apt-get install colmap).";
  s.positionals = {"PHOTO_DIR", "OUT"};
  s.min_positionals = 2;
  s.max_positionals = 2;
  s.flags = {
      {"config", "FILE.yaml",
       "options of the reconstruction from a YAML file (as reconstruct)", ""},
      {"threads", "N", "worker threads, 0 = one per core (run.threads)",
       "run.threads"},
      {"max-image-size", "N",
       "longest side of the undistorted images and the depth maps, pixels "
       "(image.max_image_size; default 1600 here)",
       "image.max_image_size"},
      {"matcher", "NAME",
       "auto (exhaustive up to 50 photos, else sequential), exhaustive or "
       "sequential (photos in file-name order, e.g. a walk or video)",
       ""},
      {"single-camera", "",
       "all photos come from one camera with a fixed zoom: one shared set of "
       "intrinsics (default: one per photo)",
       ""},
      {"colmap", "PATH", "the colmap program (default: colmap in PATH)", ""},
      {"force", "",
       "redo every stage (default: a finished camera stage in OUT/dense is "
       "kept, finished views are resumed)",
       ""},
  };
  s.epilog =
      "Example: wild_mvs photos ~/photos/fountain /tmp/fountain "
      "--max-image-size 1200\n"
      "Options of the reconstruction (--mvs.*, --fusion.*, --meshing.*) are "
      "passed to 'wild_mvs reconstruct'.";
  return s;
}

bool IsPhoto(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* e : {".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp",
                        ".ppm", ".pgm", ".webp"})
    if (ext == e) return true;
  return false;
}

// Photo file names (relative to dir, sub-folders included), sorted.
std::vector<std::string> ListPhotos(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file(ec) && IsPhoto(it->path()))
      out.push_back(fs::relative(it->path(), dir, ec).string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// One colmap stage: progress line, the run, its log on failure.
struct ColmapRunner {
  std::string colmap;    // executable path
  std::string log_dir;   // OUT/colmap/log
  int total_stages = 5;  // 4 colmap stages + reconstruct
  double cpu = 0;        // CPU-seconds of the colmap processes

  void Run(int stage, const std::string& what,
           const std::vector<std::string>& args) {
    std::vector<std::string> argv = {colmap};
    argv.insert(argv.end(), args.begin(), args.end());
    const std::string log = log_dir + "/" + args[0] + ".log";
    std::error_code ec;
    fs::remove(log, ec);
    std::cerr << "[" << stage << "/" << total_stages << "] " << what
              << " (colmap " << args[0] << ") ..." << std::flush;
    const ProcessResult r = RunProcess(argv, log);
    cpu += r.cpu_seconds;
    std::cerr << " " << std::fixed << std::setprecision(1) << r.seconds
              << " s, " << r.cpu_seconds << " CPU-s\n";
    if (r.exit_code != 0) {
      std::string cmd;
      for (const std::string& a : argv) cmd += (cmd.empty() ? "" : " ") + a;
      throw Error(Msg("colmap ", args[0], " failed (exit status ", r.exit_code,
                      "); the command was\n  ", cmd, "\nlast lines of ", log,
                      ":\n", TailOfFile(log, 15)));
    }
  }
};

std::string ThreadsArg(int threads) {
  return std::to_string(threads > 0 ? threads : -1);  // -1: all cores
}

struct SparseModel {
  std::string dir;
  size_t images = 0, points = 0;
  std::vector<std::string> names;
};

// The models the mapper wrote in sparse_dir (sub-folders 0, 1, ...),
// largest first.
std::vector<SparseModel> ReadModels(const std::string& sparse_dir) {
  std::vector<SparseModel> models;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(sparse_dir, ec)) {
    if (!e.is_directory(ec) ||
        DetectColmapModel(e.path().string()) == ColmapFormat::kNone)
      continue;
    const Scene s = ReadColmapModel(e.path().string());
    SparseModel m;
    m.dir = e.path().string();
    m.images = s.views.size();
    m.points = s.points.size();
    for (const View& v : s.views) m.names.push_back(v.name);
    models.push_back(m);
  }
  std::sort(models.begin(), models.end(),
            [](const SparseModel& a, const SparseModel& b) {
              return a.images != b.images ? a.images > b.images : a.dir < b.dir;
            });
  return models;
}

// A number from OUT/summary.json ("key": value), 0 when absent.
double SummaryValue(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const size_t p = text.find("\"" + key + "\":");
  if (p == std::string::npos) return 0;
  return std::atof(text.c_str() + p + key.size() + 3);
}

// The largest model, after the checks: some model at all, at least 3
// photos and half of them registered; a split is reported.
SparseModel ChooseModel(const std::string& sparse_dir, size_t photos) {
  const std::vector<SparseModel> models = ReadModels(sparse_dir);
  Require(!models.empty(), sparse_dir,
          ": COLMAP could not register any photos (no two photos with "
          "enough matches to start from): the photos must overlap, each "
          "part of the scene seen from several positions; see ",
          fs::path(sparse_dir).parent_path().string(), "/log/mapper.log");
  const SparseModel& best = models[0];
  if (models.size() > 1) {
    std::ostringstream parts;
    for (const SparseModel& m : models)
      parts << (&m == &models[0] ? "" : ", ") << fs::path(m.dir).filename()
            << ": " << m.images << " photos";
    std::cerr << "note: COLMAP split the photos into " << models.size()
              << " separate models (" << parts.str()
              << "), each in its own coordinate frame, so they cannot be "
                 "fused; using the largest, "
              << best.dir << ", and leaving out the other "
              << photos - best.images
              << " photos (more photos between the parts join them)\n";
  }
  const bool enough = best.images >= 3 && 2 * best.images >= photos;
  Require(enough, sparse_dir, ": only ", best.images, " of ", photos,
          " photos registered",
          models.size() > 1 ? " in the largest model" : "",
          " (at least 3 and at least half are needed): the photos overlap too "
          "little or are too different; see the logs in ",
          fs::path(sparse_dir).parent_path().string(), "/log");
  return best;
}

}  // namespace

int RunPhotos(const CommandArgs& argv) {
  ReconstructConfig config;
  OptionCommand command(PhotosSpec(), argv, &config);
  if (command.PrintHelpIfAsked(std::cout)) return 0;
  command.Configure();
  const Args& args = command.args();
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = CpuSeconds();
  const std::string photo_dir = args.positional(0), out = args.positional(1);
  const bool force = args.Has("force");
  std::error_code ec;
  Require(fs::is_directory(photo_dir, ec), photo_dir, ": not a folder");
  const std::string matcher_flag = args.Get("matcher", "auto");
  if (matcher_flag != "auto" && matcher_flag != "exhaustive" &&
      matcher_flag != "sequential") {
    throw UsageError(Msg("option --matcher: unknown matcher '", matcher_flag,
                         "' (auto, exhaustive, sequential)"));
  }
  const std::string colmap_name = args.Get("colmap", "colmap");
  const std::string colmap = FindExecutable(colmap_name);
  Require(!colmap.empty(), colmap_name,
          colmap_name.find('/') == std::string::npos
              ? ": not found in PATH: install COLMAP (Debian: apt-get install "
                "colmap) or give its path with --colmap PATH"
              : ": not an executable file (--colmap PATH)");
  const std::vector<std::string> photos = ListPhotos(photo_dir);
  Require(photos.size() >= 3, photo_dir, ": ", photos.size(),
          " photos (.jpg, .png, .tif, ...) found; at least 3 are needed");
  const int max_size = config.image.max_image_size > 0
                           ? config.image.max_image_size
                           : kDefaultMaxImageSize;
  const std::string threads = ThreadsArg(config.run.threads);
  const std::string colmap_dir = out + "/colmap", dense = out + "/dense";
  fs::create_directories(colmap_dir + "/log", ec);
  Require(!ec && fs::is_directory(colmap_dir), out,
          ": cannot create the output folder: ",
          ec ? ec.message() : std::string("not a folder"));
  const bool exhaustive =
      matcher_flag == "exhaustive" ||
      (matcher_flag == "auto" &&
       static_cast<int>(photos.size()) <= kMaxExhaustivePhotos);
  std::cerr << "photos: " << photos.size() << " in " << photo_dir << "; "
            << (exhaustive ? "exhaustive" : "sequential")
            << " matching; images up to " << max_size << " px; colmap "
            << colmap << "\n";

  ColmapRunner run{colmap, colmap_dir + "/log"};
  size_t registered = 0, sparse_points = 0;
  if (!force && IsColmapDenseWorkspace(dense)) {
    const Scene s = ReadColmapModel(dense + "/sparse");
    registered = s.views.size();
    sparse_points = s.points.size();
    std::cerr << "[1-4/5] cameras: " << dense
              << " exists, kept (--force recomputes)\n";
  } else {
    const std::string db = colmap_dir + "/database.db";
    const std::string sparse = colmap_dir + "/sparse";
    fs::remove(db, ec);
    fs::remove_all(sparse, ec);
    fs::remove_all(dense, ec);
    fs::create_directories(sparse, ec);
    std::vector<std::string> extract = {"feature_extractor",
                                        "--database_path",
                                        db,
                                        "--image_path",
                                        photo_dir,
                                        "--SiftExtraction.use_gpu",
                                        "0",
                                        "--SiftExtraction.num_threads",
                                        threads,
                                        "--ImageReader.single_camera",
                                        args.Has("single-camera") ? "1" : "0"};
    run.Run(1, "features", extract);
    if (exhaustive) {
      run.Run(2, "matching every pair",
              {"exhaustive_matcher", "--database_path", db,
               "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
               threads});
    } else {
      run.Run(2, "matching neighbours in file-name order",
              {"sequential_matcher", "--database_path", db,
               "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
               threads});
    }
    try {
      run.Run(3, "cameras and sparse points",
              {"mapper", "--database_path", db, "--image_path", photo_dir,
               "--output_path", sparse, "--Mapper.num_threads", threads,
               "--Mapper.abs_pose_min_num_inliers", kMinPoseInliers,
               "--Mapper.abs_pose_min_inlier_ratio", kMinPoseInlierRatio});
    } catch (const Error&) {
      // The mapper fails when it finds no pair to start from: that is the
      // "nothing registered" error below.
      if (!ReadModels(sparse).empty()) throw;
    }
    const SparseModel model = ChooseModel(sparse, photos.size());
    registered = model.images;
    sparse_points = model.points;
    std::cerr << "      " << registered << " of " << photos.size()
              << " photos registered, " << sparse_points << " sparse points ("
              << model.dir << ")\n";
    run.Run(4, "undistorted images",
            {"image_undistorter", "--image_path", photo_dir, "--input_path",
             model.dir, "--output_path", dense, "--output_type", "COLMAP",
             "--max_image_size", std::to_string(max_size)});
  }

  // The reconstruction, with the options given here.
  std::cerr << "[5/5] wild_mvs reconstruct " << dense << " " << out << "\n";
  CommandArgs rec = {dense, out, "--max-image-size", std::to_string(max_size)};
  if (args.Has("config")) {
    rec.push_back("--config");
    rec.push_back(args.Get("config"));
  }
  for (const Args::Assignment& a : args.core_assignments()) {
    if (a.option == "image.max_image_size") continue;
    rec.push_back("--" + a.option);
    rec.push_back(a.value);
  }
  if (force) rec.push_back("--force");
  const int status = RunReconstruct(rec);
  if (status != 0) return status;

  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  const double cpu = CpuSeconds() - cpu0 + run.cpu;
  const std::string summary = out + "/summary.json";
  std::cout << "photos summary: " << registered << " of " << photos.size()
            << " photos registered, " << sparse_points << " sparse points, "
            << static_cast<long>(SummaryValue(summary, "fused_points"))
            << " points, "
            << static_cast<long>(SummaryValue(summary, "mesh_faces"))
            << " faces; " << std::fixed << std::setprecision(1) << secs
            << " s, " << cpu << " CPU-s (colmap " << run.cpu << "); cloud "
            << out << "/fused.ply, mesh " << out
            << "/mesh.ply, COLMAP workspace " << dense << "\n";
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
