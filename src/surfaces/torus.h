#pragma once
// The `torus` surface type: a ring torus (major radius > minor radius), or an azimuth range of it.
#include "surfaces/revolution.h"
#include "surfaces/surface.h"

namespace radiosa {

// P(s, t) = center + (R + r cos v) radial(u) + r sin v axis, u = the azimuth range at s,
// v = 2 pi t (t = 0 on the outer equator, t = 1/4 on top). dP/ds x dP/dt points outward.
class TorusSurface final : public Surface {
public:
    TorusSurface(const Vec3& center, const Vec3& unit_axis, double major, double minor,
                 const AngleRange& angles, bool inward);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    // The quartic in the ray parameter, its roots isolated (util/polynomial.h).
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    // Exact: |dP/du x dP/dv| = r (R + r cos v).
    double area(double s0, double s1, double t0, double t1) const override;
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    // Exact: linear in a . radial(u), a cosine in v.
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    // Four circle arcs: two about the axis (t fixed), two around the tube (s fixed).
    bool patch_contour(double s0, double s1, double t0, double t1,
                       std::vector<ContourPiece>* out) const override;
    // The outer half (cos v >= 0: t in [0, 1/4] or [3/4, 1]), where each point's tangent plane
    // supports the whole torus.
    bool on_convex_hull(double s0, double s1, double t0, double t1) const override;
    // On the outer half, seen from outside: the least of n . (c - P) over the rectangle is exact
    // (linear in radial(u) . (c - center), whose range is exact, then a cosine in v).
    bool faces_ball(double s0, double s1, double t0, double t1, const BoundingSphere& b,
                    bool back) const override;
    bool chords_never_cross() const override { return false; }
    bool front_segments_escape() const override { return false; }
    bool sees_itself() const override { return true; }
    bool wraps_in_s() const override { return m_angles.full(); }
    bool wraps_in_t() const override { return true; }
    void write_key(ByteWriter& w) const override;

private:
    Vec3 m_center;
    AzimuthFrame m_frame;
    double m_R, m_r;
    AngleRange m_angles;
};

}  // namespace radiosa
