// Copyright wild_mvs authors. Cheap image size probe.
//
// Reads only the header of PNG, JPEG, PNM (P1-P6, PF/Pf) and BMP files;
// other formats fall back to decoding with OpenCV. The size is the stored
// one (EXIF orientation ignored, as LoadViewImage does).
#pragma once

#include <string>

namespace wild_mvs {

struct ImageSize {
  int width = 0, height = 0;
};

// Throws Error naming the file when it is missing or not a readable image.
ImageSize ReadImageSize(const std::string& path);

}  // namespace wild_mvs
