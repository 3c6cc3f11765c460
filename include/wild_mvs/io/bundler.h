// Copyright wild_mvs authors. Bundler v0.3 output (bundle.out + list.txt),
// the structure-from-motion pipeline of the paper.
//
// Conversions (Bundler -> wild_mvs):
//  - Bundler's camera looks down -z with y up: R' = diag(1,-1,-1) R,
//    t' = diag(1,-1,-1) t gives our x-right / y-down / z-forward frame.
//  - Intrinsics: fx = fy = f; principal point = image centre. Bundler's 2-D
//    coordinates are relative to the image centre with y up, where the
//    centre is ((w-1)/2, (h-1)/2) in 0-based (integer-centre) pixel
//    coordinates (as Bundler/Bundle2PMVS use), i.e. (w/2, h/2) in wild_mvs's
//    convention: u = x + w/2, v = h/2 - y, and cx = w/2, cy = h/2.
//  - Image size: read from each image file's header (ReadImageSize).
//  - Distortion: Bundler's radial model acts on normalised coordinates p
//    (p' = f (1 + k1 |p|^2 + k2 |p|^4) p), which is exactly OpenCV's radial
//    model with fx = fy = f, so View::distortion = kRadial(k1, k2), images
//    are undistorted at load, and the observations are undistorted here.
//  - Cameras with f = 0 are unregistered: they get no View, their
//    observations are dropped (points left with no observation too), and
//    Scene::source lists them.
//  - View::name = the image path as written in list.txt (relative to the
//    list file's folder, leading "./" removed); image_path = image_root/name.
//  - Observation::scale = 0 (bundle.out has no feature scale).
#pragma once

#include <string>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// image_root defaults to the folder of list_file. Throws Error naming the
// file and line for malformed input, and naming the image when one is
// missing or unreadable.
Scene ReadBundler(const std::string& bundle_file, const std::string& list_file,
                  const std::string& image_root = "");

}  // namespace wild_mvs
