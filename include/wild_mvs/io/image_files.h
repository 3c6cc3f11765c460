// Copyright wild_mvs authors. View images and masks read from files: the
// loaders behind ImageCache (the core sees no file paths) and the one mask
// rule.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "wild_mvs/core/image.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// Loads a view's image from View::image_path (8/16-bit, grey or colour;
// EXIF orientation ignored), undistorts it when the view has lens
// distortion, checks that its size is the file size the view expects
// (View::file_width/height, else the camera's), resizes it to the camera
// (area averaging) and converts it with ToLinearRgb. Throws Error naming
// the file and the problem (missing, unreadable, wrong size).
// A JPEG at least four times the camera's size (a downscaled view, e.g. a
// 24 MP photo and --max-image-size 1000) is decoded reduced by libjpeg
// (JpegReductionFactor), then resized by the exact remaining factor (2x or
// more, area averaging), so the camera stays exact.
cv::Mat LoadViewImage(const View& view, const ImageOptions& options);

// The reduction factor of the JPEG decode of a file_width x file_height
// image for a camera of width x height: the largest of 8, 4, 2 with
// file size >= 2 x factor x camera size on both axes (the decoded image,
// ceil(file size / factor), holds at least twice the camera's resolution:
// the area-averaged resize after it keeps the full decode's quality), else 1.
int JpegReductionFactor(int file_width, int file_height, int width, int height);

// The view's image file as decoded, before undistortion and resizing: a JPEG
// decoded at 1/factor (ceil(file size / factor) pixels) when
// JpegReductionFactor allows it, else the full file (checked against the
// size the view expects); *factor (optional) receives the factor used.
cv::Mat ReadViewImageFile(const View& view, int* factor);

// An ImageCache loader that reads the views of `scene` (which must outlive
// it) with LoadViewImage.
ImageCache::Loader MakeSceneLoader(const Scene& scene,
                                   const ImageOptions& options);

// Masks. The rule, in one place:
// - File names (AssignMasks): in the mask folder DIR, the mask of image NAME
//   (stem S) is the first of DIR/NAME.png (COLMAP's convention), DIR/S.png,
//   DIR/NAME that exists; views without one have no mask (all pixels used).
// - Values (LoadViewMask): read as 8-bit grey; 0 = ignore the pixel, any
//   other value = use it.
// - Size: the mask must have the camera's size or the image file's size
//   (View::file_width/height, e.g. before LimitImageSize downscaled the
//   camera); a file-size mask is resized to the camera, nearest neighbour.
//   Any other size, or an unreadable file, is an Error naming the file.

// Sets View::mask_path of the views of *scene from folder `dir` (rule
// above). Returns the number of views that got a mask; throws Error naming
// `dir` when it is not a folder or no view has a mask in it.
int AssignMasks(Scene* scene, const std::string& dir);

// The view's mask (CV_8U, 0 = ignore) at its camera's resolution, or an
// empty Mat when View::mask_path is empty (rule above).
cv::Mat LoadViewMask(const View& view);

}  // namespace wild_mvs
