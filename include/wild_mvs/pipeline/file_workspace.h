// Copyright wild_mvs authors. The depth pipeline's workspace in an output
// folder OUT (the layout of `wild_mvs reconstruct`, docs/ARCHITECTURE.md):
// per view with image stem S, OUT/depth/S.pfm, OUT/normal/S.pfm,
// OUT/confidence/S.pfm, OUT/cameras/S.txt, OUT/preview/S_*.png and the log
// OUT/log/S.json, written last (a view is complete once its log exists).
// With the consistency filter the matched maps go to OUT/raw in the same
// layout and the filtered ones to OUT; without it both stages are OUT.
// Keys are view indices of the scene; files name neighbours by image name.
#pragma once

#include <string>
#include <unordered_map>

#include "wild_mvs/core/scene.h"
#include "wild_mvs/pipeline/depth_workspace.h"

namespace wild_mvs {

class FileDepthWorkspace : public DepthWorkspace {
 public:
  // `scene` must outlive the workspace. filter: the maps are filtered
  // (matched maps in OUT/raw).
  FileDepthWorkspace(const Scene& scene, std::string out, bool filter);

  bool Has(Stage stage, int key) const override;
  // Neighbour names not in the scene are left out.
  std::shared_ptr<const DepthMap> Read(Stage stage, int key) const override;
  // kRaw: the maps and a log of the matching report. kFinal of a filtered
  // result: the maps and the raw log with the kept samples and a
  // "consistency" member (samples_before, kept, neighbor_maps).
  void Write(Stage stage, int key, const ViewResult& result) override;

  // The folder of `stage`.
  const std::string& Folder(Stage stage) const;
  // "samples" of the view's log at `stage`, -1 when unreadable.
  long long Samples(Stage stage, int key) const override;

 private:
  const Scene& scene_;
  std::string out_, raw_;
  std::unordered_map<std::string, int> index_;  // view name -> key
};

// True when view `stem`'s files in folder `dir` are complete (maps, camera
// and log; the log is written last).
bool ViewOutputsComplete(const std::string& dir, const std::string& stem);

}  // namespace wild_mvs
