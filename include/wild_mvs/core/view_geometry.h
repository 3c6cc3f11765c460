// Copyright wild_mvs authors. Geometry of view pairs shared by the pair
// selection of the sparse tracker and by global view selection: how much of
// one camera's frustum another sees, and where two optical axes meet.
#pragma once

#include <vector>

#include "wild_mvs/core/camera.h"

namespace wild_mvs {

// Fraction of the sample points of cam's frustum that project into other's
// image in front of it. The samples are the centres of an 8 x 6 grid of
// cam's image back-projected to each depth in `depths` (z in cam); 0 when
// `depths` is empty.
double FrustumGridOverlap(const Camera& cam, const Camera& other,
                          const std::vector<double>& depths);

// Depth of closest approach of the optical axes of a and b: the distance
// along a's axis from a's centre to the point of a's axis closest to b's
// axis, written to *depth. False (and *depth untouched) when the axes are
// near-parallel, i.e. 1 - cos^2 of their angle is below min_sin2, or when
// the closest points lie behind either centre.
bool AxesClosestApproachDepth(const Camera& a, const Camera& b, double min_sin2,
                              double* depth);

}  // namespace wild_mvs
