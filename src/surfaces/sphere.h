#pragma once
// The `sphere` surface type: a sphere or a part of one (caps, hemispheres, zones, lunes), facing
// outward or inward.
#include "surfaces/revolution.h"
#include "surfaces/surface.h"

namespace radiosa {

// Sphere: azimuth phi0 + span s about +z, polar angle from +z falling linearly from theta_bottom
// at t = 0 to theta_top at t = 1 (a whole sphere: azimuth 2 pi s, polar angle pi (1 - t)).
class SphereSurface final : public Surface {
public:
    SphereSurface(const Vec3& center, double radius, bool inward, const AngleRange& angles = AngleRange{},
                  double theta_top = 0.0, double theta_bottom = kPi);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    void point_and_normal(double s, double t, Vec3* x, Vec3* n) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    bool blocks(const Ray& ray, double t_min, double t_max) const override;
    std::optional<double> front_distance(const Ray& ray, double t_min, double t_max) const override;
    std::optional<Ball> front_distance_of_ball() const override {
        if (!whole_sphere()) return std::nullopt;
        return Ball{m_center, m_radius, m_orientation};
    }
    void front_hits(std::size_t n, const Ray* const* rays, const double* dist, const double* limit,
                    std::optional<SurfaceHit>* out) const override;
    double area(double s0, double s1, double t0, double t1) const override;
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    // Exact: a . P is A(phi) sin(theta) + a_z cos(theta), each factor a shifted cosine.
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    std::optional<BoundingSphere> sphere() const override { return BoundingSphere{m_center, m_radius}; }
    bool chords_never_cross() const override { return true; }
    bool front_segments_escape() const override { return m_orientation > 0.0; }
    bool sees_itself() const override { return m_orientation < 0.0; }
    bool back_segments_escape() const override { return m_orientation < 0.0; }
    bool back_sees_itself() const override { return m_orientation > 0.0; }
    double max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const override {
        if (glm::length(p - m_center) <= 1e-14 * m_radius) return m_radius;
        return Surface::max_distance_from_point(p, s0, s1, t0, t1);
    }
    std::optional<ConvexSolid> convex_solid() const override {
        return ConvexSolid{false, m_center, Vec3(0, 0, 1), m_radius};
    }
    std::pair<double, double> sphere_angles(double s, double t) const override {
        return {m_angles.at(s), theta(t)};
    }
    // Caps only: every azimuth, from a pole to a polar angle short of the other pole.
    std::optional<SphericalCap> spherical_cap() const override {
        if (!m_angles.full() || whole_sphere()) return std::nullopt;
        if (m_top == 0.0 && m_bottom < kPi)
            return SphericalCap{m_center, Vec3(0, 0, 1), m_radius, m_radius * std::cos(m_bottom)};
        if (m_bottom == kPi && m_top > 0.0)
            return SphericalCap{m_center, Vec3(0, 0, -1), m_radius, -m_radius * std::cos(m_top)};
        return std::nullopt;
    }
    bool whole_sphere() const override { return m_angles.full() && m_top == 0.0 && m_bottom == kPi; }
    bool wraps_in_s() const override { return m_angles.full(); }
    bool pole_at_t0() const override { return m_bottom == kPi; }
    bool pole_at_t1() const override { return m_top == 0.0; }
    void write_key(ByteWriter& w) const override;

private:
    // The hit at dist whose direction from the centre has azimuth phi and polar angle th, if
    // those are inside the ranges.
    std::optional<SurfaceHit> hit_at_angles(double dist, double phi, double th, bool front) const;
    double theta(double t) const { return (m_bottom - m_top) * (1.0 - t) + m_top; }
    // The sines and cosines of the azimuth (p) and the polar angle (t) at (s, t): what point()
    // and partials() are made of, so that point_and_normal() takes them once.
    struct Trig {
        double sp, cp, st, ct;
    };
    Trig trig(double s, double t) const;
    Vec3 point_of(const Trig& a) const;
    void partials_of(const Trig& a, Vec3* dPds, Vec3* dPdt) const;
    Vec3 m_center;
    double m_radius;
    AngleRange m_angles;
    double m_top, m_bottom;  // polar angles of t = 1 and t = 0
};

}  // namespace radiosa
