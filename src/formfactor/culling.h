#pragma once
// Work proven useless, left out of the form-factor integrals: pairs that cannot exchange energy,
// and surfaces that cannot come between a pair (so no segment between them is tested).
#include <array>
#include <span>
#include <utility>
#include <vector>

#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"

namespace radiosa {

// True when surface k is proven unable to block any segment from a point of surface a to one
// of surface b by what k is to them: k is one of them, or the other side of one, and its
// segments escape it (Surface::chords_never_cross, front_segments_escape,
// back_segments_escape). *own tells whether k is one of them or their other side.
bool own_surface_clear(const SceneGeometry& g, int a, int b, int k, bool* own);

// A segment between points on one closed side of a plane cannot cross it: ea and eb are the
// ends' ranges of signed distance from the plane, eps the length below which one is zero.
inline bool one_side_of_plane(std::pair<double, double> ea, std::pair<double, double> eb, double eps) {
    return (ea.first >= -eps && eb.first >= -eps) || (ea.second <= eps && eb.second <= eps);
}

// Every segment from a point of the convex hull of `a` to a point of the hull of `b` passes
// deeper than eps inside the ball, proven at one fraction t along them: the points
// (1 - t) x + t y fill the hull of the corners' combinations (1 - t) a_i + t b_j, so the
// farthest of those from the centre is the farthest of all. That distance is convex in t
// (a maximum of convex functions), and t is found by ternary search. With both hulls outside
// the ball, each such segment crosses its surface: a whole sphere hides them from each other.
bool segments_through_ball(std::span<const Vec3> a, std::span<const Vec3> b, const BoundingSphere& ball,
                           double eps);

class Culling {
public:
    explicit Culling(const SceneGeometry& g);
    double eps() const { return m_eps; }  // lengths below this are zero at the scene's scale

    // True when no energy can pass between the two patches: either one lies entirely behind or
    // in the plane of the other (this covers patches of one planar surface), or both are
    // patches of one surface that cannot see itself.
    bool culled(int i, int j) const;
    // False when surface k is proven unable to block any segment between the two patches.
    bool can_block(int i, int j, int k) const;
    // False when surface k is proven unable to block any segment between patch i and any
    // patch of surface b, so can_block(i, j, k) is false for each of them: for a polygon patch
    // and a quad, from the hull of the patch and the whole quad. True when nothing is proven.
    bool can_block_any(int i, int b, int k) const;
    // Surfaces that might block a segment between the two patches (every surface when
    // culling is off); the rest are proven unable to.
    void occluders(int i, int j, bool culling, std::vector<int>* out, FormFactorStats* st) const;

private:
    bool hull_misses(const Patch& pi, const Patch& pj, const Surface& s) const;
    // Polygon a sees only the back of curved patch b, from each of its points.
    bool sees_only_back(const Patch& a, const Patch& b) const;
    bool slab_separates(int i, int j, int k) const;
    const SceneGeometry& m_geo;
    double m_eps;
    // Exact extents along x, y and z (Surface::linear_range), asked for every pair a slab is
    // tried on: per surface (whole) and per patch.
    using AxisRanges = std::array<std::pair<double, double>, 3>;
    std::vector<AxisRanges> m_surface_axes, m_patch_axes;
};

}  // namespace radiosa
