// Copyright wild_mvs authors. Preparing a loaded Scene for the CLI commands:
// dataset flags, image size limit, masks, view selection.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/image_files.h"

namespace wild_mvs {
namespace cli {

// DatasetOptions from the --model / --images / --format flags of `args`.
DatasetOptions MakeDatasetOptions(const std::string& path, const Args& args);

// Downscales every view whose image's longest side exceeds max_size pixels:
// the camera becomes Camera::Scaled (View::file_width/height keep the file's
// size, so LoadViewImage resizes at load) and the view's track observations
// and feature scales are scaled with it. max_size = 0: no change. Returns
// the number of views changed.
int LimitImageSize(Scene* scene, int max_size);

// AssignMasks and LoadViewMask (the mask rule): wild_mvs/io/image_files.h.

// Indices of the views named in a comma-separated list (image names or
// stems); "" = all views. Throws UsageError naming an unknown entry.
std::vector<int> SelectViews(const Scene& scene, const std::string& list);

// `--shard K/N`: share K (1..N) of N independent processes.
struct Shard {
  int index = 1, count = 1;  // K, N; 1/1 = the whole list
  bool IsWhole() const { return count == 1; }
};
// Parses "K/N" (1 <= K <= N). Throws UsageError naming --shard.
Shard ParseShard(const std::string& text);
// The views of shard K/N: `views` sorted by scene index, then every N-th
// from position K-1 (round robin: neighbouring views, which cost about the
// same, go to different shards). A function of the view list only, so every
// process computes the same split.
std::vector<int> ShardViews(std::vector<int> views, const Shard& shard);

}  // namespace cli
}  // namespace wild_mvs
