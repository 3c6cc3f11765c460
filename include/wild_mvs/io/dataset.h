// Copyright wild_mvs authors. Loading a dataset folder of any supported
// format into a Scene, with automatic layout detection.
//
// Formats and the layouts detected (first match wins, in this order):
//  colmap      COLMAP text or binary model in DIR/sparse/0/, DIR/sparse/,
//              DIR/, DIR/colmap_sift_gt/, DIR/colmap/, then any sub-folder
//              (depth <= 2, sorted). Images: the first of
//              M/images, M/images_undistorted, M, then the same for up to
//              3 parents of the model folder M, then DIR/images, DIR, in
//              which every image
//              NAME exists with the camera's size (e.g. DIR/images/ for
//              DIR/sparse/0, DIR for the shared colmap_sift_gt/ models).
//  bundler     DIR/bundle/bundle.out or DIR/bundle.out, with list.txt in
//              DIR/ or beside bundle.out; image paths relative to list.txt.
//  middlebury  DIR/*_par.txt (exactly one), images in DIR/.
//  strecha     DIR/cameras/*.camera, images in DIR/images/.
//  projmatrix  DIR/cameras/*.projmatrix, images under DIR/images/ (matched by
//              frame number, see projmatrix.h).
// Overrides: model_dir (folder of the model; for bundler/middlebury it may be
// the bundle.out / *_par.txt file itself) and images_dir (the folder image
// names are relative to).
// After reading: View::image_path set, Scene::source filled, Scene::Validate()
// called, and (check_images) every image must exist with the camera's size
// (header probe, see image_size.h): otherwise Error naming the file.
#pragma once

#include <string>

#include "wild_mvs/core/scene.h"
// The images and masks of a loaded dataset are read with image_files.h.
#include "wild_mvs/io/image_files.h"

namespace wild_mvs {

enum class DatasetFormat {
  kAuto,
  kColmap,
  kBundler,
  kMiddlebury,
  kStrecha,
  kProjMatrix
};

// "auto", "colmap", "bundler", "middlebury", "strecha", "projmatrix".
const char* DatasetFormatName(DatasetFormat f);
// Throws Error naming `option` for an unknown name.
DatasetFormat ParseDatasetFormat(const std::string& name,
                                 const std::string& option = "--format");

struct DatasetOptions {
  std::string path;        // dataset folder (required unless model_dir set)
  std::string model_dir;   // override: model folder / file ("" = detect)
  std::string images_dir;  // override: image folder ("" = detect)
  DatasetFormat format = DatasetFormat::kAuto;  // kAuto = detect
  bool check_images = true;  // images exist and match the camera size
  // Throws Error naming the option and the bad value.
  void Check() const;
};

// What LoadDataset found (for `wild_mvs info`).
struct DatasetLayout {
  DatasetFormat format = DatasetFormat::kAuto;
  std::string model;       // model folder or file
  std::string images_dir;  // "" when decided per format after reading
};

// Detects the format and model location; throws Error listing what was
// looked for when nothing matches.
DatasetLayout DetectDatasetLayout(const DatasetOptions& options);

Scene LoadDataset(const DatasetOptions& options);

// Checks that every view's image exists and has the size of its camera
// (file_width/file_height when set). Throws Error naming the file.
void CheckSceneImages(const Scene& scene);

}  // namespace wild_mvs
