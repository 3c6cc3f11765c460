// Copyright wild_mvs authors. The switches of the ablation experiments: each
// turns one part of the method off (true = on, the default). They are
// reachable from the command line (--ablation.*, and --preset paper sets the
// paper's pipeline) and the tests, never from the ROS nodes, which always
// run the full method.
#pragma once

#include <string>

#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

struct AblationOptions {
  bool linearize = true;             // inverse sRGB curve at image load
  bool color = true;                 // match colour; false = grey images
  bool rescaling = true;             // rescaling (paper 5.1, end)
  bool local_view_selection = true;  // false = the best global views, fixed
  bool optimize_normal = true;       // false = fronto-parallel patches
  bool optimize_color_scale = true;  // false = colour scales fixed to 1
  bool photometric_offset = true;    // I_R = c I_V + b; false = c I_V (paper)
  bool consistency = true;   // filter of the finished maps (beyond paper)
  bool planar_prior = true;  // fill from triangle planes (beyond paper)
  // The explain test (MpgcOptions::explain_margin; beyond the paper).
  bool explain_test = true;
  // Bilateral window weights (MpgcOptions::bilateral_*; beyond the paper);
  // false = the plain window.
  bool bilateral_window = true;
  // Multi-scale: fill the map's empty pixels where the window cannot match
  // from the view matched at half its working size, itself filled from half
  // that (coarse_fill.h; beyond the paper); false = one size (paper).
  bool coarse_fill = true;
};

// Registers the switches under `prefix` (e.g. "ablation").
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     AblationOptions* options);

}  // namespace wild_mvs
