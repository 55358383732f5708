#pragma once
// The `sphere` surface type: a whole sphere, facing outward or inward.
#include "surfaces/surface.h"

namespace radiosa {

// Sphere: azimuth 2 pi s, polar angle pi (1 - t) from +z.
class SphereSurface final : public Surface {
public:
    SphereSurface(const Vec3& center, double radius, bool inward);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
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
    std::optional<ConvexSolid> convex_solid() const override {
        return ConvexSolid{false, m_center, Vec3(0, 0, 1), m_radius};
    }
    bool wraps_in_s() const override { return true; }
    bool pole_at_t0() const override { return true; }
    bool pole_at_t1() const override { return true; }
    void write_key(ByteWriter& w) const override;

private:
    Vec3 m_center;
    double m_radius;
};

}  // namespace radiosa
