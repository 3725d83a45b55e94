// Shared by the complete stage's tests: parts from labels, meshes in one.
#pragma once

#include <string>
#include <vector>

#include "g2p/complete.h"
#include "g2p/model.h"

namespace g2p::test {

// One part holding every face of `mesh`.
std::vector<Part> single_part(const Mesh& mesh, int label);

// Appends `b` to `a` (indices shifted); returns the first face index of b.
int append_mesh(Mesh& a, const Mesh& b);

// The parts of a model labelled with its ground truth from labels.json
// (materials marked "ignore" count as Other), as the project stage would
// partition them.
std::vector<Part> ground_truth_parts(const Model& model, const std::string& key);

}  // namespace g2p::test
