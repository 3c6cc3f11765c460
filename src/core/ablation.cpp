// Copyright wild_mvs authors.
#include "wild_mvs/core/ablation.h"

namespace wild_mvs {

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     AblationOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry->Add(key("linearize"), &o->linearize,
                "apply the inverse sRGB curve at image load (match in linear "
                "radiance); false = match the encoded values");
  registry->Add(key("color"), &o->color, "match colour images; false = grey");
  registry->Add(key("rescaling"), &o->rescaling,
                "rescale the reference and its neighbours to a common scale "
                "(paper 5.1); false = original sizes");
  registry->Add(key("local_view_selection"), &o->local_view_selection,
                "local view selection per pixel (paper 5.2); false = the best "
                "global views, fixed");
  registry->Add(key("optimize_normal"), &o->optimize_normal,
                "optimise the patch normal; false = fronto-parallel");
  registry->Add(key("optimize_color_scale"), &o->optimize_color_scale,
                "optimise per-view colour scales; false = fixed to 1");
  registry->Add(key("photometric_offset"), &o->photometric_offset,
                "photometric model I_R = c I_V + b (an offset per view and "
                "channel); false = c I_V (paper)");
  registry->Add(key("consistency"), &o->consistency,
                "filter the finished depth maps against their neighbours' "
                "(mvs.consistency); false = keep every sample (paper)");
  registry->Add(key("planar_prior"), &o->planar_prior,
                "fill where growth stopped from the planes of triangles of "
                "confident samples; false = growth alone (paper)");
  registry->Add(key("explain_test"), &o->explain_test,
                "region growing does not expand from a match that R's window "
                "explains worse than the views explain each other "
                "(mvs.mpgc.explain_*); false = every match expands (paper)");
  registry->Add(key("bilateral_window"), &o->bilateral_window,
                "weight the matching window bilaterally (mvs.mpgc.bilateral_*)"
                "; false = the plain window (paper)");
  registry->Add(key("coarse_fill"), &o->coarse_fill,
                "multi-scale: fill the empty pixels where the window cannot "
                "match from the view matched at half the size; false = one "
                "size (paper)");
}

}  // namespace wild_mvs
