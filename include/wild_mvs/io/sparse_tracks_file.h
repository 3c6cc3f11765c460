// Copyright wild_mvs authors. The exact record of a scene's sparse tracks,
// OUT/sparse/tracks.txt: written by `wild_mvs reconstruct` when it computed
// the tracks of a dataset without sparse points, read back by later runs on
// the same OUT (resumed runs and --shard K/N processes) so that every
// process seeds its views from the same points, bit for bit.
//
// Text, one record a line: the options the tracks depend on ("option KEY
// VALUE"), the views in scene order ("view WIDTH HEIGHT NAME", the camera
// size after downscaling) and the points ("point X Y Z R G B ERROR N" then
// N "obs VIEW X Y SCALE" lines). Numbers are written with 17 significant
// digits, which read back to the same doubles (the COLMAP text model beside
// it is for people and other tools and is rounded to the file resolution).
#pragma once

#include <string>
#include <vector>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// Writes scene.points and the views' names and sizes to `path` atomically.
// `fingerprint`: "KEY VALUE" lines of the options the tracks depend on.
void WriteSparseTracks(const std::string& path, const Scene& scene,
                       const std::vector<std::string>& fingerprint);

// Reads `path` into *points when it was written for a scene with the same
// views (names and camera sizes, same order) and the same fingerprint;
// otherwise returns false and says why in *why (e.g. "option
// image.max_image_size: 640 in the file, 320 now"). A malformed file throws
// Error naming the file and line.
bool ReadSparseTracks(const std::string& path, const Scene& scene,
                      const std::vector<std::string>& fingerprint,
                      std::vector<SparsePoint>* points, std::string* why);

}  // namespace wild_mvs
