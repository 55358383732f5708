#pragma once
// The form factor between two planar convex polygons that nothing comes between, by the
// contour-integral form of the double area integral (Stokes applied twice; Sparrow 1963,
// Mitalas & Stephenson 1966, Schröder & Hanrahan 1993):
//   A_a F_ab = 1/(2 pi) * sum over edge pairs (k of a, l of b) of (d_k . d_l) *
//              integral over edge k of integral over edge l of ln r,
// with each polygon first cut to the other's front half-space (where the kernel is positive),
// so partly hidden, touching, edge- and vertex-sharing pairs need no special case. The inner
// integral along edge l is in closed form; the outer one, along edge k, is an adaptive
// Gauss-Kronrod (7, 15) rule whose integrand is smooth except for r ln r kinks where edges are
// collinear (shared edges). By default every entry comes out exact to round-off at any gap and
// scale; given an absolute tolerance, the outer rule stops once its error estimate is within it,
// and parallel edges (every edge pair that counts between two axis-aligned rectangles:
// perpendicular ones add nothing) take both integrals in closed form where its rounding allows
// (pairs whose entry only needs a tolerance, such as the hierarchy's pairs of patches, pay for
// that and no more).
#include "util/math.h"

namespace radiosa {

struct PolygonPair {
    double value = 0.0;   // A_a F_ab = A_b F_ba (area units)
    double error = 0.0;   // bound on |value - exact|: quadrature estimates plus rounding
    int evaluations = 0;  // inner closed forms evaluated (a cost measure)
};

// The double integral of ln(r / rho), with ln rho = `log_rho`, over two parallel segments
// whose lines lie `h` apart, positions measured along a common axis: the first covers
// [0, len_a], the second [b0, b1] (b0 <= b1). `error` bounds its rounding. Exact at touching
// and collinear segments. polygon_to_polygon takes it for every pair of parallel edges.
struct ParallelEdges {
    double value = 0.0;
    double error = 0.0;
};
ParallelEdges parallel_edges_log_integral(double len_a, double b0, double b1, double h, double log_rho);

// a[0..na) and b[0..nb): planar, convex, counter-clockwise about their front normals, at most
// 8 vertices each. Zero when either lies wholly behind or in the other's plane. `abs_tol`: the
// error wanted on A_a F_ab (area units), 0 for round-off.
PolygonPair polygon_to_polygon(const Vec3* a, int na, const Vec3* b, int nb, double abs_tol = 0.0);

}  // namespace radiosa
