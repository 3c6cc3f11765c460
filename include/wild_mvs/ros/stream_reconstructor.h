// Copyright wild_mvs authors. Moved to the ROS-free streaming layer:
// include "wild_mvs/stream/stream_reconstructor.h" (namespace wild_mvs).
// Kept for the parameter binder (params.h), whose option structs hold
// StreamOptions; remove once nothing includes this path.
#pragma once

#include "wild_mvs/stream/stream_reconstructor.h"
