// A pipeline result for a model far larger than the samples, for what must
// stay quick at 1M+ triangles (summary.html's 3D view).
#pragma once

#include "g2p/pipeline.h"

namespace g2p::test {

// A wavy grid of 2 (nx - 1) (ny - 1) triangles, 1 mm apart, in two parts
// (Wood on the left half, Metal on the right); no views, stages or asset.
// The default is 1,209,600 triangles.
PipelineResult large_grid_result(int nx = 721, int ny = 841);

}  // namespace g2p::test
