// Copyright wild_mvs authors.
#include "wild_mvs/io/dataset.h"

#include <algorithm>
#include <filesystem>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/bundler.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/image_size.h"
#include "wild_mvs/io/middlebury.h"
#include "wild_mvs/io/projmatrix.h"
#include "wild_mvs/io/strecha.h"

namespace wild_mvs {

namespace fs = std::filesystem;

namespace {

bool IsDir(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}
bool IsFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

std::vector<fs::path> SortedSubdirs(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory(ec)) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<fs::path> FilesWithSuffix(const fs::path& dir,
                                      const std::string& suffix) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (e.is_regular_file(ec) && n.size() > suffix.size() &&
        n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
      out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string FindColmapModel(const fs::path& base) {
  std::vector<fs::path> cand = {base / "sparse" / "0", base / "sparse", base,
                                base / "colmap_sift_gt", base / "colmap"};
  for (const fs::path& d : cand)
    if (DetectColmapModel(d.string()) != ColmapFormat::kNone) return d.string();
  for (const fs::path& d1 : SortedSubdirs(base)) {
    if (DetectColmapModel(d1.string()) != ColmapFormat::kNone)
      return d1.string();
  }
  for (const fs::path& d1 : SortedSubdirs(base))
    for (const fs::path& d2 : SortedSubdirs(d1))
      if (DetectColmapModel(d2.string()) != ColmapFormat::kNone)
        return d2.string();
  return "";
}

std::string FindBundleOut(const fs::path& base) {
  for (const fs::path& p :
       {base / "bundle" / "bundle.out", base / "bundle.out"})
    if (IsFile(p)) return p.string();
  return "";
}

std::string FindListFile(const fs::path& bundle_out, const fs::path& base) {
  const fs::path d = bundle_out.parent_path();
  for (const fs::path& p :
       {base / "list.txt", d / "list.txt", d.parent_path() / "list.txt"})
    if (!p.empty() && IsFile(p)) return p.string();
  throw Error(Msg(bundle_out.string(), ": no list.txt found (looked in ",
                  base.string(), ", ", d.string(), " and its parent)"));
}

std::string FindPar(const fs::path& dir) {
  const auto pars = FilesWithSuffix(dir, "_par.txt");
  if (pars.empty()) return "";
  if (pars.size() > 1)
    throw Error(Msg(dir.string(), ": several *_par.txt files (",
                    pars[0].filename().string(), ", ",
                    pars[1].filename().string(),
                    "...): choose one with --model"));
  return pars[0].string();
}

// Returns "" when every view's image exists in `dir` with the right size,
// else a description of the first problem.
std::string ImagesProblem(const Scene& s, const fs::path& dir, int* found) {
  *found = 0;
  std::string problem;
  for (const View& v : s.views) {
    const fs::path p = dir / v.name;
    if (!IsFile(p)) {
      if (problem.empty()) problem = Msg(p.string(), ": image file is missing");
      continue;
    }
    ++*found;
    if (!problem.empty()) continue;
    try {
      const ImageSize sz = ReadImageSize(p.string());
      if (sz.width != v.camera.width || sz.height != v.camera.height)
        problem =
            Msg(p.string(), ": image is ", sz.width, "x", sz.height,
                " but its camera says ", v.camera.width, "x", v.camera.height);
    } catch (const Error& e) {
      problem = e.what();
    }
  }
  return problem;
}

// Chooses the COLMAP image folder (see dataset.h).
std::string ChooseColmapImages(const Scene& s, const fs::path& model,
                               const fs::path& base) {
  std::vector<fs::path> cand;
  fs::path a = fs::absolute(model).lexically_normal();
  const fs::path b = fs::absolute(base).lexically_normal();
  // The model folder and up to 3 parents (also above DIR, so that a model
  // folder given as the dataset, e.g. DIR/sparse/0, finds DIR/images).
  for (int depth = 0; depth < 4 && !a.empty(); ++depth) {
    cand.push_back(a / "images");
    cand.push_back(a / "images_undistorted");
    cand.push_back(a);
    if (a == a.parent_path()) break;
    a = a.parent_path();
  }
  cand.push_back(b / "images");
  cand.push_back(b);
  std::string best_problem;
  int best_found = -1;
  for (const fs::path& c : cand) {
    if (!IsDir(c)) continue;
    int found = 0;
    const std::string problem = ImagesProblem(s, c, &found);
    if (problem.empty()) return c.string();
    if (found > best_found) {
      best_found = found;
      best_problem = problem;
    }
  }
  throw Error(Msg(model.string(), ": cannot find the images of the model (",
                  best_found <= 0 ? "looked in images/, images_undistorted/ "
                                    "and the model's parent folders"
                                  : best_problem,
                  "); use --images DIR"));
}

void SetImagePaths(Scene* s, const std::string& dir) {
  for (View& v : s->views) v.image_path = (fs::path(dir) / v.name).string();
}

}  // namespace

const char* DatasetFormatName(DatasetFormat f) {
  switch (f) {
    case DatasetFormat::kAuto:
      return "auto";
    case DatasetFormat::kColmap:
      return "colmap";
    case DatasetFormat::kBundler:
      return "bundler";
    case DatasetFormat::kMiddlebury:
      return "middlebury";
    case DatasetFormat::kStrecha:
      return "strecha";
    case DatasetFormat::kProjMatrix:
      return "projmatrix";
  }
  return "?";
}

DatasetFormat ParseDatasetFormat(const std::string& name,
                                 const std::string& option) {
  for (DatasetFormat f : {DatasetFormat::kAuto, DatasetFormat::kColmap,
                          DatasetFormat::kBundler, DatasetFormat::kMiddlebury,
                          DatasetFormat::kStrecha, DatasetFormat::kProjMatrix})
    if (name == DatasetFormatName(f)) return f;
  throw Error(Msg(option, " = '", name,
                  "' is not a dataset format (auto, colmap, bundler, "
                  "middlebury, strecha, projmatrix)"));
}

void DatasetOptions::Check() const {
  Require(!path.empty() || !model_dir.empty(),
          "dataset: a dataset folder (or --model) is required");
  std::error_code ec;
  if (!path.empty())
    Require(fs::is_directory(path, ec), "dataset path '", path,
            "' is not a folder");
  if (!model_dir.empty())
    Require(fs::exists(model_dir, ec), "--model '", model_dir,
            "' does not exist");
  if (!images_dir.empty())
    Require(fs::is_directory(images_dir, ec), "--images '", images_dir,
            "' is not a folder");
}

DatasetLayout DetectDatasetLayout(const DatasetOptions& o) {
  o.Check();
  const fs::path base =
      o.path.empty() ? fs::path(o.model_dir) : fs::path(o.path);
  DatasetLayout L;
  const DatasetFormat want = o.format;
  auto wants = [&](DatasetFormat f) {
    return want == DatasetFormat::kAuto || want == f;
  };
  if (!o.model_dir.empty()) {
    const fs::path m(o.model_dir);
    if (wants(DatasetFormat::kColmap) && IsDir(m) &&
        DetectColmapModel(m.string()) != ColmapFormat::kNone)
      return {DatasetFormat::kColmap, m.string(), o.images_dir};
    if (wants(DatasetFormat::kBundler)) {
      if (IsFile(m) && m.extension() == ".out")
        return {DatasetFormat::kBundler, m.string(), o.images_dir};
      if (IsDir(m) && IsFile(m / "bundle.out"))
        return {DatasetFormat::kBundler, (m / "bundle.out").string(),
                o.images_dir};
    }
    if (wants(DatasetFormat::kMiddlebury)) {
      if (IsFile(m) && m.filename().string().size() > 8 &&
          m.filename().string().find("_par.txt") != std::string::npos)
        return {DatasetFormat::kMiddlebury, m.string(), o.images_dir};
      if (IsDir(m)) {
        const std::string par = FindPar(m);
        if (!par.empty())
          return {DatasetFormat::kMiddlebury, par, o.images_dir};
      }
    }
    if (wants(DatasetFormat::kStrecha) && IsDir(m) &&
        !FilesWithSuffix(m, ".camera").empty())
      return {DatasetFormat::kStrecha, m.string(), o.images_dir};
    if (wants(DatasetFormat::kProjMatrix) && IsDir(m) &&
        !FilesWithSuffix(m, ".projmatrix").empty())
      return {DatasetFormat::kProjMatrix, m.string(), o.images_dir};
    throw Error(Msg("--model '", o.model_dir, "': no ",
                    want == DatasetFormat::kAuto ? "" : DatasetFormatName(want),
                    want == DatasetFormat::kAuto ? "" : " ",
                    "model found there (COLMAP cameras/images files, "
                    "bundle.out, *_par.txt, *.camera or *.projmatrix)"));
  }
  if (wants(DatasetFormat::kColmap)) {
    const std::string m = FindColmapModel(base);
    if (!m.empty()) return {DatasetFormat::kColmap, m, o.images_dir};
  }
  if (wants(DatasetFormat::kBundler)) {
    const std::string b = FindBundleOut(base);
    if (!b.empty()) return {DatasetFormat::kBundler, b, o.images_dir};
  }
  if (wants(DatasetFormat::kMiddlebury)) {
    const std::string par = FindPar(base);
    if (!par.empty()) return {DatasetFormat::kMiddlebury, par, o.images_dir};
  }
  if (wants(DatasetFormat::kStrecha) &&
      !FilesWithSuffix(base / "cameras", ".camera").empty())
    return {DatasetFormat::kStrecha, (base / "cameras").string(),
            o.images_dir.empty() ? (base / "images").string() : o.images_dir};
  if (wants(DatasetFormat::kProjMatrix) &&
      !FilesWithSuffix(base / "cameras", ".projmatrix").empty())
    return {DatasetFormat::kProjMatrix, (base / "cameras").string(),
            o.images_dir.empty() ? (base / "images").string() : o.images_dir};
  throw Error(
      Msg(base.string(), ": no ",
          want == DatasetFormat::kAuto ? "" : DatasetFormatName(want),
          want == DatasetFormat::kAuto ? "" : " ",
          "dataset found (looked for a COLMAP model in sparse/0, sparse, ., "
          "colmap_sift_gt and sub-folders; bundle/bundle.out or bundle.out; "
          "*_par.txt; cameras/*.camera; cameras/*.projmatrix)"));
}

void CheckSceneImages(const Scene& scene) {
  for (const View& v : scene.views) {
    Require(!v.image_path.empty(), scene.source, ": image '", v.name,
            "' has no image path");
    const ImageSize sz = ReadImageSize(v.image_path);
    const int w = v.file_width > 0 ? v.file_width : v.camera.width;
    const int h = v.file_height > 0 ? v.file_height : v.camera.height;
    Require(sz.width == w && sz.height == h, v.image_path, ": image is ",
            sz.width, "x", sz.height, " but its camera says ", w, "x", h);
  }
}

Scene LoadDataset(const DatasetOptions& o) {
  const DatasetLayout L = DetectDatasetLayout(o);
  const fs::path base =
      o.path.empty() ? fs::path(o.model_dir) : fs::path(o.path);
  Scene s;
  std::string images_dir = L.images_dir;
  switch (L.format) {
    case DatasetFormat::kColmap:
      s = ReadColmapModel(L.model);
      if (images_dir.empty()) images_dir = ChooseColmapImages(s, L.model, base);
      SetImagePaths(&s, images_dir);
      break;
    case DatasetFormat::kBundler: {
      const std::string list = FindListFile(L.model, base);
      s = ReadBundler(L.model, list, images_dir);
      if (images_dir.empty())
        images_dir = fs::path(list).parent_path().string();
      break;
    }
    case DatasetFormat::kMiddlebury:
      if (images_dir.empty())
        images_dir = fs::path(L.model).parent_path().string();
      s = ReadMiddleburyPar(L.model, images_dir);
      break;
    case DatasetFormat::kStrecha:
      if (images_dir.empty())
        images_dir = (fs::path(L.model).parent_path() / "images").string();
      s = ReadStrechaCameras(L.model, images_dir);
      break;
    case DatasetFormat::kProjMatrix:
      if (images_dir.empty())
        images_dir = (fs::path(L.model).parent_path() / "images").string();
      s = ReadProjectionMatrices(L.model, images_dir);
      break;
    case DatasetFormat::kAuto:
      throw Error("LoadDataset: format not detected");
  }
  s.source =
      Msg(DatasetFormatName(L.format), ": ", s.source, "; images ", images_dir);
  s.Validate();
  if (o.check_images) CheckSceneImages(s);
  return s;
}

}  // namespace wild_mvs
