#pragma once
// What the hierarchy's refinement and its nodes share (formfactor/hierarchy.h): the sample
// points of a node, and its rectangle of parameters. Internal to src/formfactor.
#include <vector>

#include "formfactor/cubature.h"
#include "formfactor/hierarchy.h"

namespace radiosa {

// A Gauss point of a node.
struct Sample {
    Vec3 x;
    Vec3 n;       // unit front normal
    double w;     // area weight
    double u, v;  // where in the node, each in [-1, 1] along s and t
};

// The node's rectangle of its surface's parameters.
Rect node_rect(const SceneGeometry& g, const HierarchyNode& n);

// m x m Gauss points of every node, node after node (s inner, t outer).
std::vector<Sample> node_samples(const SceneGeometry& g, const Hierarchy& h, int m);

}  // namespace radiosa
