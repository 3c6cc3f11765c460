// Copyright wild_mvs authors. `wild_mvs sparse DATASET OUT_MODEL_DIR`.
#include <chrono>
#include <iostream>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/option_command.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/cli/run_steps.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/cli/specs.h"
#include "wild_mvs/io/colmap.h"

namespace wild_mvs {
namespace cli {

int RunSparse(const CommandArgs& argv) {
  ReconstructConfig config;
  OptionCommand command(SparseSpec(), argv, &config);
  if (command.PrintHelpIfAsked(std::cout)) return 0;
  command.Configure();
  const Args& args = command.args();

  const auto start = std::chrono::steady_clock::now();
  const std::string out_dir = args.positional(1);
  Scene scene = LoadDataset(MakeDatasetOptions(args.positional(0), args));
  const int scaled = LimitImageSize(&scene, config.image.max_image_size);
  std::cerr << "loaded " << scene.views.size() << " views from "
            << scene.source;
  if (scaled) std::cerr << " (" << scaled << " downscaled)";
  std::cerr << "\n";
  const std::size_t had = scene.points.size();
  if (had) {
    std::cerr << "note: the dataset's " << had
              << " sparse points are replaced by tracks from the known "
                 "poses\n";
  }
  ThreadPool pool(config.run.threads);
  const SparseSummary s = ComputeSceneTracks(&scene, config, &pool, std::cerr);
  WriteColmapText(scene, out_dir);
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  std::cout << "wrote " << out_dir
            << "/{cameras,images,points3D}.txt: " << s.points << " points, "
            << s.observations << " observations, median track length "
            << s.median_track_length << ", median reprojection error "
            << s.median_error << " px (" << secs << " s)\n";
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
