// Copyright wild_mvs authors. COLMAP sparse models (text and binary).
//
// Reads cameras / images / points3D (.txt or .bin) into a Scene:
//  - One View per registered image, in file order, named by the image NAME
//    (relative to the image folder). View::image_path = images_dir/NAME when
//    an images_dir is given, else empty (LoadDataset fills it).
//  - Camera models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV.
//    The pinhole part becomes View::camera, the distortion View::distortion
//    (kRadial: k1[, k2]; kOpenCV: k1 k2 p1 p2). Fisheye and all other models
//    are rejected with an Error naming the file, line and model.
//  - Pixel convention: COLMAP's (top-left pixel centre at (0.5, 0.5)) is
//    wild_mvs's, so no shift. Track observations are undistorted
//    (cv::undistortPoints, with the 0.5 px shift OpenCV needs) so that they
//    match the pinhole camera; Observation::scale = 0 (unknown).
//  - images.txt POINT3D_IDs are not needed: tracks come from points3D
//    (IMAGE_ID, POINT2D_IDX), both checked.
//  - points3D.{txt,bin} may be absent (cameras + poses only): no points.
// Every malformed input throws wild_mvs::Error naming the file, the line
// (text) or byte offset (binary) and the problem.
#pragma once

#include <string>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

enum class ColmapFormat { kNone, kText, kBinary };

// Which COLMAP model, if any, is in `dir` (needs cameras + images; text is
// preferred when both exist).
ColmapFormat DetectColmapModel(const std::string& dir);

// Reads the model in model_dir (text or binary, detected). Throws Error when
// there is none.
Scene ReadColmapModel(const std::string& model_dir,
                      const std::string& images_dir = "");
Scene ReadColmapText(const std::string& model_dir,
                     const std::string& images_dir = "");
Scene ReadColmapBinary(const std::string& model_dir,
                       const std::string& images_dir = "");

// Writes cameras.txt, images.txt, points3D.txt into `dir` (created if
// missing), each atomically. One camera per view (PINHOLE, or OPENCV when
// the view has distortion; at the file resolution when View::file_width is
// set), IMAGE_ID = CAMERA_ID = view index + 1, POINT3D_ID = point index + 1.
// Observations are re-distorted for views with distortion, so reading the
// model back gives the same scene.
void WriteColmapText(const Scene& scene, const std::string& dir);

}  // namespace wild_mvs
