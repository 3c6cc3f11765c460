// Copyright wild_mvs authors. Planar prior (beyond the paper; after Xu and
// Tao, "Planar Prior Assisted PatchMatch Multi-View Stereo", AAAI 2020):
// where region growing stopped because a window carries too little texture
// for a match of its own, the surface between confident samples is
// hypothesised to be the plane of their triangle, and the triangle's plane
// is kept where the photo-consistency of all its pixels together prefers it.
#pragma once

#include <opencv2/core.hpp>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/mpgc.h"
#include "wild_mvs/core/region_growing.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {

struct PlanarPriorStats {
  int vertices = 0;        // samples the triangulation used
  int triangles = 0;       // triangles with empty pixels, tested
  int triangles_kept = 0;  // whose plane the photo-consistency preferred
  int samples_added = 0;   // empty pixels filled from kept planes
  double cpu_seconds = 0;  // CPU time on pool threads (RunParallel)
};

// The triangle test's statistic (step 3 below) over a triangle's pixels.
// A pixel where the plane or a shifted copy has no score
// (PatchMatcher::PlaneScore returns -1: R's window has no texture, or fewer
// than two views of N see it) is no evidence either way and is not
// counted.
class PlaneEvidence {
 public:
  // One pixel's scores (mean NCC, in [-1, 1]; -1 = none) of the window on
  // the plane, and on the plane moved nearer and farther along the rays.
  void Add(double on_plane, double nearer, double farther);
  // Pixels counted (those with all three scores).
  int samples() const { return n_; }
  // At least 8 pixels counted (kMinTestSamples), and the mean of the paired
  // differences on_plane - (nearer + farther) / 2 is positive and more
  // than 3 of its standard errors (kSigmas).
  bool Supports() const;
  // The mean score on the plane over the pixels counted; -1 with none.
  double MeanScore() const;

 private:
  double sum_ = 0, sum_d_ = 0, sum_d2_ = 0;
  int n_ = 0;
};

// The steps, on R's map after region growing:
// 1. Vertices: the most confident sample of every kVertexCell x kVertexCell
//    cell of the map; in a cell without one, a sparse point R sees there
//    (`points`: R's own features, with their triangulated depth).
// 2. 2-D Delaunay triangulation of the vertices in R; each triangle names
//    the plane through its three camera-frame points. The plane must face
//    R at its corners (kMinFacing) and lie within kMaxVertexNormalDeg of
//    the normal of every corner that is a match (a triangle across a depth
//    edge tilts towards the rays).
// 3. A triangle with empty pixels is tested on a grid of up to
//    kTestSamples of its pixels: at each, the mean of the best two NCCs
//    over N of the window on the plane, and on the same plane moved
//    nearer and farther along the rays by the depth that shifts the
//    triangle's centre kShiftPx pixels in the median view of N. Kept when the
//    plane's score beats the mean of the two shifted ones by kSigmas
//    standard errors of the paired differences (PlaneEvidence: the plane
//    explains the images better than its neighbours in depth, for the
//    triangle as a whole, where no single window could tell).
// 4. The empty pixels inside kept triangles take the plane: depth, its
//    normal, and the confidence of its mean score.
// Pixels with a sample are never changed. mask (CV_8U, may be empty):
// 0 = not filled. The geometric-consistency filter checks the filled
// samples against the neighbours' maps like any other.
void FillFromPlanarPrior(const PatchContext& context, const MpgcOptions& mpgc,
                         const LocalViewSelectionOptions& local,
                         const std::vector<Seed>& points, const cv::Mat& mask,
                         ThreadPool* pool, DepthMap* map,
                         PlanarPriorStats* stats);

}  // namespace wild_mvs
