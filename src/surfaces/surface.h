#pragma once
// The interface every surface type implements: P(s, t), (s, t) in [0,1]^2, with exact partial
// derivatives and exact ray intersection. Each type lives in its own file (quad.cpp,
// sphere.cpp, ...) and is listed once in registry.cpp. Curved surfaces are never replaced by polygons
// anywhere in radiosa.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "util/bytes.h"
#include "util/math.h"

namespace radiosa {

struct Plane {
    Vec3 normal;    // unit, pointing to the front side
    double offset;  // normal . x = offset on the plane
    double signed_distance(const Vec3& x) const { return glm::dot(normal, x) - offset; }
};

struct SurfaceHit {
    double dist = 0.0;  // ray parameter
    double s = 0.0;
    double t = 0.0;
    bool front = false;  // the ray arrives on the front side
};

enum class HitSide { Any, FrontOnly };

// A segment's end that lies on a surface is a crossing of it, known only to the rounding of the
// end's coordinates across the surface. Along a segment that grazes the surface there, that
// rounding spans a stretch of the ray parameter beside the end, within which a crossing cannot
// be told from the end's own: 1e-14 of the coordinates' size (the surface's `extent` plus the
// lengths of the ray's origin and direction) over |unit_normal . ray.dir|, at most 1e-6. A
// crossing closer than this to t_min or t_max is taken as that end, not as a crossing in between.
inline double end_margin(const Ray& ray, const Vec3& unit_normal, double extent) {
    const double size = extent + glm::length(ray.origin) + glm::length(ray.dir);
    return std::min(1e-6, 1e-14 * size / std::abs(glm::dot(unit_normal, ray.dir)));
}

// A convex solid: the ball |y - center| <= radius, or the round infinite cylinder or cone about
// the line through center along the unit vector axis: the points whose distance from that line
// is at most radius + slope h, h = (y - center) . axis (slope 0: a cylinder; otherwise the
// nappe of the cone on the side where that radius is positive).
struct ConvexSolid {
    bool cylinder = false;  // about a line (a cylinder, or a cone when slope != 0)
    Vec3 center{0.0};
    Vec3 axis{0.0, 0.0, 1.0};
    double radius = 0.0;
    double slope = 0.0;
    // The solid's radius at height h along the axis from center.
    double radius_at(double h) const { return radius + slope * h; }
};

// A whole flat disk or annulus: the points of the plane through `center` with unit normal
// `normal` whose distance from the centre lies between `inner_radius` and `radius`.
struct FlatDisk {
    Vec3 center{0.0};
    Vec3 normal{0.0, 0.0, 1.0};
    double radius = 0.0, inner_radius = 0.0;
};

// A whole round tube: radius `radius` about the segment from `base` along the unit vector
// `axis` for `length`.
struct RoundTube {
    Vec3 base{0.0};
    Vec3 axis{0.0, 0.0, 1.0};
    double length = 0.0, radius = 0.0;
};

// A whole round truncated cone or cylinder, open at both ends: radius `radius` at `base`,
// `top_radius` at base + length axis (unit axis), linear in between; top_radius 0 is a cone
// to its apex.
struct RoundFrustum {
    Vec3 base{0.0};
    Vec3 axis{0.0, 0.0, 1.0};
    double length = 0.0, radius = 0.0, top_radius = 0.0;
    // The radius of the surface's plane section at height h along the axis (any h: the
    // infinite cone's, negative beyond its apex).
    double radius_at(double h) const { return radius + (top_radius - radius) * (h / length); }
    // A cylinder as a round tube (between its end planes it blocks what the infinite cylinder
    // blocks: formfactor/column_shadow.h); nothing for a cone.
    std::optional<RoundTube> column() const {
        if (top_radius != radius) return std::nullopt;
        return RoundTube{base, axis, length, radius};
    }
};

// A whole spherical cap (every angle about its axis): the points of the sphere (centre, radius)
// with (p - center) . axis >= height, -radius < height < radius, unit axis. Its solid, the ball
// cut by that plane, is convex; its open end is the disk of radius sqrt(radius^2 - height^2)
// about center + height axis.
struct SphericalCap {
    Vec3 center{0.0};
    Vec3 axis{0.0, 0.0, 1.0};
    double radius = 0.0, height = 0.0;
    double rim_radius() const { return std::sqrt(std::max(0.0, radius * radius - height * height)); }
};

// A piece of a patch's boundary: the segment from a to b, or the arc
// center + radius (cos u e1 + sin u e2) for u running from `from` to `to` (either order), or the
// cubic Bezier curve with control points q (from q[0] = a to q[3] = b).
struct ContourPiece {
    bool arc = false;
    bool cubic = false;
    Vec3 a{0.0}, b{0.0};
    Vec3 center{0.0}, e1{0.0}, e2{0.0};
    double radius = 0.0, from = 0.0, to = 0.0;
    std::array<Vec3, 4> q{};
};

class Surface {
public:
    virtual ~Surface() = default;

    virtual Vec3 point(double s, double t) const = 0;
    virtual void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const = 0;
    // The unnormalised front normal n = +-(dP/ds x dP/dt); |n| ds dt is the area element.
    Vec3 normal(double s, double t) const {
        Vec3 ds, dt;
        partials(s, t, &ds, &dt);
        return normal_of(ds, dt);
    }
    // point(s, t) and normal(s, t) at once, the same values: the outer integrals of form factors
    // take both at every node, and a surface whose two share their sines and cosines (a
    // sphere's) computes them once.
    virtual void point_and_normal(double s, double t, Vec3* x, Vec3* n) const {
        *x = point(s, t);
        *n = normal(s, t);
    }

    // The nearest crossing with dist in (t_min, t_max) (only front-side ones if asked).
    virtual std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                                HitSide side) const = 0;
    // Whether the segment (t_min, t_max) of the ray meets the surface on either side: always
    // intersect(ray, t_min, t_max, HitSide::Any).has_value(), which a type may answer faster
    // (occlusion tests need no surface parameters).
    virtual bool blocks(const Ray& ray, double t_min, double t_max) const {
        return intersect(ray, t_min, t_max, HitSide::Any).has_value();
    }
    // The distance of intersect(ray, t_min, t_max, HitSide::FrontOnly), bit for bit, without
    // the hit's parameters, which a type may answer faster (a BVH's candidates need only their
    // distance: the nearest one's parameters are found once).
    virtual std::optional<double> front_distance(const Ray& ray, double t_min, double t_max) const {
        const auto h = intersect(ray, t_min, t_max, HitSide::FrontOnly);
        return h ? std::optional<double>(h->dist) : std::nullopt;
    }
    // Set when front_distance is sphere_front_distance(ray, center, radius, orientation, t_min,
    // t_max) of surfaces/sphere_hit.h (a whole sphere), which a BVH may then call inline.
    struct Ball {
        Vec3 center{0.0};
        double radius = 0.0;
        double orientation = 1.0;
    };
    virtual std::optional<Ball> front_distance_of_ball() const { return std::nullopt; }
    // The hits of n rays whose front_distance(*rays[i], 0, limit[i]) was dist[i]: out[i] is
    // intersect(*rays[i], 0, limit[i], HitSide::FrontOnly), its distance bit for bit and its
    // parameters within 1e-15 of that call's. A type may find them together (a whole sphere's
    // angles in SIMD lanes): an image's nearest hits are found this way (geometry/ray_index.h).
    virtual void front_hits(std::size_t n, const Ray* const* rays, const double* dist, const double* limit,
                            std::optional<SurfaceHit>* out) const {
        (void)dist;
        for (std::size_t i = 0; i < n; ++i) out[i] = intersect(*rays[i], 0.0, limit[i], HitSide::FrontOnly);
    }

    // Exact area of the parameter rectangle [s0,s1] x [t0,t1].
    virtual double area(double s0, double s1, double t0, double t1) const = 0;
    // A sphere containing the image of the parameter rectangle.
    virtual BoundingSphere bound(double s0, double s1, double t0, double t1) const = 0;
    // The range [min, max] of a . P(s, t) over the parameter rectangle: where a plane with normal
    // a meets the region (form-factor events, formfactor/events.h). Exact for the built-in types;
    // this default, from bound(), may be wider but never narrower.
    virtual std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                                   double t1) const {
        const BoundingSphere b = bound(s0, s1, t0, t1);
        const double m = glm::dot(a, b.center), r = glm::length(a) * b.radius;
        return {m - r, m + r};
    }
    // The supporting plane of a planar surface.
    virtual std::optional<Plane> plane() const { return std::nullopt; }
    // True when every patch is exactly the convex polygon of its four corner points P(s0,t0),
    // P(s1,t0), P(s1,t1), P(s0,t1) (a quad's patches): form factors then use the closed-form
    // point-to-polygon integral and the corners' extent. A planar surface whose patches have
    // curved edges (a disk's sectors) is planar but returns false.
    virtual bool patches_are_polygons() const { return false; }
    // Centre and radius of a spherical surface.
    virtual std::optional<BoundingSphere> sphere() const { return std::nullopt; }
    // A spherical surface's axes (columns: local x, y, z; its parameter poles lie on local +-z
    // and azimuth 0 on local +x): the identity unless a transform rotated it.
    virtual Mat3 sphere_axes() const { return Mat3(1.0); }
    // A spherical surface's azimuth and polar angle (about sphere_axes, from local +z) at (s, t).
    virtual std::pair<double, double> sphere_angles(double s, double t) const {
        return {2.0 * kPi * s, kPi * (1.0 - t)};
    }
    // True for a whole sphere (every azimuth, pole to pole).
    virtual bool whole_sphere() const { return false; }

    // True when a chord between two of its points never crosses the surface elsewhere
    // (planes, spheres): then it can be left out of the occlusion test for its own pairs.
    virtual bool chords_never_cross() const = 0;
    // True when a segment that leaves one of its points on the front side never meets the
    // surface again (planes, outward spheres), whatever the other end.
    virtual bool front_segments_escape() const = 0;
    // True when a patch can see another patch of the same surface (concave side in front).
    virtual bool sees_itself() const = 0;
    // The boundary of the parameter rectangle, run counter-clockwise about the front normal,
    // when it is made of segments, circle arcs and cubic curves (disk sectors, cylinder, cone
    // and torus patches, Bezier patches): the contour
    // form of the inner form-factor integral (formfactor/contour_receiver.h). False otherwise.
    virtual bool patch_contour(double, double, double, double, std::vector<ContourPiece>*) const {
        return false;
    }
    // The convex solid whose boundary holds the whole surface (a ball, or an infinite round
    // cylinder or cone), if there is one: a segment from a point inside it meets the surface only at its
    // ends, and the surface's concave side faces every point inside.
    virtual std::optional<ConvexSolid> convex_solid() const { return std::nullopt; }
    // The whole surface as a flat disk or annulus (every angle), if it is one: its shadow seen
    // from a point is the cone over its rims (formfactor/disk_shadow.h).
    virtual std::optional<FlatDisk> flat_disk() const { return std::nullopt; }
    // The whole surface as a round cylinder or truncated cone (every angle), if it is one: what
    // it hides of a polygon seen from a point is in closed form (formfactor/tube_shadow.h).
    virtual std::optional<RoundFrustum> round_frustum() const { return std::nullopt; }
    // The whole surface as a spherical cap (a dome or a bowl: every angle, one polar end at a
    // pole), if it is one: what it hides of a polygon seen from a point is in closed form
    // (formfactor/cap_shadow.h).
    virtual std::optional<SphericalCap> spherical_cap() const { return std::nullopt; }
    // The largest distance of a point of the parameter rectangle from the line through p along
    // the unit vector u: exact where the line is the surface's own axis and for polygon patches;
    // this default, from bound(), may be larger but never smaller.
    virtual double max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                          double t1) const {
        const BoundingSphere b = bound(s0, s1, t0, t1);
        const Vec3 q = b.center - p;
        return glm::length(q - glm::dot(q, u) * u) + b.radius;
    }
    // The largest distance of a point of the parameter rectangle from the point p: exact where p
    // is on the surface's own axis (its centre, for a sphere) and for polygon patches; this
    // default, from bound(), may be larger but never smaller.
    virtual double max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const {
        const BoundingSphere b = bound(s0, s1, t0, t1);
        return glm::length(b.center - p) + b.radius;
    }
    // True when every point of the ball lies on the convex side's front (the back, if `back`):
    // in front of the tangent plane of every point of the parameter rectangle, with no part of
    // the surface hiding another from it.
    virtual bool faces_ball(double, double, double, double, const BoundingSphere&, bool /*back*/) const {
        return false;
    }
    // Whether every ray from any point of the convex hull of `from` meets the parameter
    // rectangle at most once, all of it in front of those points' projection and none of it
    // seen edge-on: +1 when they see its front, -1 when they see its back, 0 when not proven
    // (the default). Then a segment from such a point to the part meets it only at its end.
    virtual int seen_once_from(std::span<const Vec3> /*from*/, double, double, double, double) const {
        return 0;
    }
    // Whether every point of the parameter rectangle lies on the boundary of the convex hull of
    // the whole surface, its tangent plane supporting the surface there (the outer half of a
    // torus): a segment to such a point from a point in front of its tangent plane meets the
    // surface nowhere else. Geometric: the same for either side. False by default.
    virtual bool on_convex_hull(double, double, double, double) const { return false; }
    // The same two answers for the surface's back side (two-sided surfaces, surfaces/placed.h).
    // The defaults are the safe ones: more occlusion tests and self pairs, never a wrong value.
    virtual bool back_segments_escape() const { return false; }
    virtual bool back_sees_itself() const { return true; }
    // +1 when the front normal is dP/ds x dP/dt, -1 when it is the opposite.
    double orientation() const { return m_orientation; }
    // Topology of the parameter domain, for averaging radiosities at shared nodes.
    virtual bool wraps_in_s() const { return false; }  // s = 0 and s = 1 coincide
    virtual bool wraps_in_t() const { return false; }  // t = 0 and t = 1 coincide (a torus's tube)
    virtual bool pole_at_t0() const { return false; }  // the whole edge t = 0 is one point
    virtual bool pole_at_t1() const { return false; }

    // The bytes this surface adds to the form-factor cache key: every parameter that changes
    // its shape, placement or orientation, exactly as given (the key test changes each one).
    virtual void write_key(ByteWriter& w) const = 0;

protected:
    // normal()'s front normal from the partials dP/ds and dP/dt.
    Vec3 normal_of(const Vec3& dPds, const Vec3& dPdt) const {
        return m_orientation * glm::cross(dPds, dPdt);
    }

    double m_orientation = 1.0;
};

}  // namespace radiosa
