#pragma once
// Outlines on the sphere of directions from a point x, made of straight pieces and arcs of up to
// two circles, and the form factor of the part of one inside a polygon's cone: what the
// closed-form shadows of a tube (tube_shadow.cpp) and of a spherical cap (cap_shadow.cpp)
// integrate. The contour integral 1/(2 pi) of n . (r x dr) / |r|^2 around the outline
// (point_polygon.h) is Lambert's term on straight pieces and the closed-form arc integral on
// arcs (circle_arc.h); it does not change when a piece moves along rays from x, so a cut by a
// plane through x closes the outline with a chord.
#include <array>

#include "formfactor/circle_arc.h"
#include "formfactor/polygon_cone.h"
#include "util/math.h"

namespace radiosa {

// A piece of an outline: the segment a -> b, or the arc of circle `rim` from angle `from` to `to`
// (either order), whose ends are a and b.
struct OutlinePiece {
    Vec3 a{0.0}, b{0.0};
    int rim = -1;  // -1: a segment
    double from = 0.0, to = 0.0;
};

// A closed outline, convex on the sphere of directions from x. Each cut by a plane through x
// adds at most a chord and splits at most one arc in two.
struct Outline {
    static constexpr int kMax = 4 + 3 * PolygonCone::kMaxEdges;
    std::array<OutlinePiece, kMax> p{};
    int n = 0;
    bool full() const { return n >= kMax; }
    void add(const OutlinePiece& q) {
        if (!full()) p[static_cast<std::size_t>(n++)] = q;
    }
    void arc(const std::array<Circle, 2>& rims, int rim, double from, double to) {
        add({rims[static_cast<std::size_t>(rim)].at(from), rims[static_cast<std::size_t>(rim)].at(to), rim,
             from, to});
    }
    void segment(const Vec3& a, const Vec3& b) { add({a, b, -1, 0.0, 0.0}); }
};

// The part of the outline where f . (y - x) >= 0: each piece's part on that side, and a chord
// wherever the outline left it and came back (both ends on the plane through x).
Outline cut_outline(const Outline& in, const Vec3& f, const Vec3& x, const std::array<Circle, 2>& rims);

// The contour integral of n . (r x dr) / |r|^2 around the outline, up to its orientation.
ContourValue integrate_outline(const Outline& o, const Vec3& x, const Vec3& n,
                               const std::array<Circle, 2>& rims);

// The form factor of the outline's part inside the polygon's cone (x's unit normal n).
ShadowValue outline_inside_cone(Outline o, const PolygonCone& cone, const Vec3& x, const Vec3& n,
                                const std::array<Circle, 2>& rims);

}  // namespace radiosa
