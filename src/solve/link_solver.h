#pragma once
// The radiosity solve over a hierarchy's links (formfactor/hierarchy.h): Jacobi sweeps of
// gather, push and pull (Hanrahan, Salzman & Aupperle 1991). Each sweep gathers, at every
// node, the irradiance sum f B_source over its links (B of a node: the area average of its
// patches'), pushes it down to the patches, sets B = E + rho H there, and pulls the averages
// back up. O(links + nodes) per sweep, all three channels at once, and the same answer for any
// thread count (every sum runs over a node's own links, in their sorted order).
#include <vector>

#include "formfactor/hierarchy.h"
#include "util/math.h"

namespace radiosa {

struct LinkSolveOptions {
    // Stop when the largest change of a sweep is below tolerance x max B (per channel).
    double tolerance = 1e-10;
    int max_sweeps = 10000;
};

struct LinkSolution {
    std::vector<Rgb> B;  // per patch
    int sweeps = 0;
    double change = 0.0;  // the last sweep's max change / max B, worst channel
};

// rho and E per patch. `start`: a warm start (the radiosities for nearby lights), else E.
// Throws Error when the sweeps do not settle within max_sweeps (no steady state).
LinkSolution solve_links(const Hierarchy& h, const std::vector<Rgb>& rho, const std::vector<Rgb>& E,
                         const LinkSolveOptions& options = {}, const std::vector<Rgb>* start = nullptr);

}  // namespace radiosa
