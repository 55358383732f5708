#pragma once
// The `quad` surface type: the bilinear map of four coplanar corners of a convex quadrilateral.
#include <array>
#include <memory>
#include <utility>

#include "surfaces/surface.h"

namespace radiosa {

// Bilinear map of four coplanar corners (a parallelogram when c0 + c2 = c1 + c3).
class QuadSurface final : public Surface {
public:
    QuadSurface(const Vec3& c0, const Vec3& c1, const Vec3& c2, const Vec3& c3);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    double area(double s0, double s1, double t0, double t1) const override;
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    // Bilinear in (s, t): the extremes lie at the corners.
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    std::optional<Plane> plane() const override { return m_plane; }
    bool patches_are_polygons() const override { return true; }
    bool chords_never_cross() const override { return true; }
    bool front_segments_escape() const override { return true; }
    bool sees_itself() const override { return false; }
    bool back_segments_escape() const override { return true; }
    bool back_sees_itself() const override { return false; }
    // A triangle (triangle.cpp): the last two corners coincide, and the edge t = 1 is one point.
    bool pole_at_t1() const override { return m_corners[2] == m_corners[3]; }
    // Exact: the distance from a line is convex, so its largest value is at a corner.
    double max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                  double t1) const override;
    double max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const override;
    void write_key(ByteWriter& w) const override;
    const std::array<Vec3, 4>& corners() const { return m_corners; }
    // Inverse of the map for a point on the plane; nullopt when outside [0,1]^2.
    std::optional<std::pair<double, double>> invert(const Vec3& x) const;

private:
    std::array<Vec3, 4> m_corners;  // as given: the cache key
    Vec3 m_p0, m_e, m_f, m_g;       // P = p0 + s e + t f + s t g
    Plane m_plane;
    Vec3 m_u, m_v;  // orthonormal in-plane axes
    // e, f, g in (u, v) coordinates, and what invert() needs of them alone: found once.
    double m_ex, m_ey, m_fx, m_fy, m_gx, m_gy, m_k2, m_exf;
};

// The triangle a, b, c as a quad whose edge t = 1 collapses to c (surfaces/triangle.cpp).
std::shared_ptr<const Surface> make_triangle(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace radiosa
