#pragma once
// The `cone` surface type: the side of a cone or a truncated cone (a frustum), open at both
// ends; the `cylinder` type (cylinder.cpp) is the frustum with equal radii.
#include "surfaces/revolution.h"
#include "surfaces/surface.h"

namespace radiosa {

// P(s, t) = base + t axis + r(t) radial(phi(s)), r(t) = radius + (top_radius - radius) t:
// t = 0 is the base circle, t = 1 the top; phi over the angle range about the axis.
class FrustumSurface final : public Surface {
public:
    FrustumSurface(const Vec3& base, const Vec3& axis, double radius, double top_radius,
                   const AngleRange& angles, bool inward);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    double area(double s0, double s1, double t0, double t1) const override;
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    // Exact: for each azimuth a . P is affine in t, and r(t) >= 0.
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    // Part of the boundary of a convex solid: a chord stays inside it, and a segment leaving
    // the outside never comes back.
    bool chords_never_cross() const override { return true; }
    bool front_segments_escape() const override { return m_orientation > 0.0; }
    bool sees_itself() const override { return m_orientation < 0.0; }
    bool back_segments_escape() const override { return m_orientation < 0.0; }
    bool back_sees_itself() const override { return m_orientation > 0.0; }
    // Two arcs (one, at an apex) and two straight generators.
    bool patch_contour(double s0, double s1, double t0, double t1,
                       std::vector<ContourPiece>* out) const override;
    // The infinite cylinder, or the nappe of the infinite cone, that the side lies on.
    std::optional<ConvexSolid> convex_solid() const override;
    // Every whole one.
    std::optional<RoundFrustum> round_frustum() const override {
        if (!m_angles.full()) return std::nullopt;
        return RoundFrustum{m_base, m_frame.axis, m_length, m_r0, m_r1};
    }
    // Exact about the surface's own axis (the rectangle's larger radius).
    double max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                  double t1) const override;
    // Exact when p is on the axis: the distance is largest on a rim.
    double max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const override;
    // Convex side: in front of every patch point's tangent plane (one per generator).
    bool faces_ball(double s0, double s1, double t0, double t1, const BoundingSphere& b,
                    bool back) const override;
    bool wraps_in_s() const override { return m_angles.full(); }
    bool pole_at_t1() const override { return m_r1 == 0.0; }
    void write_key(ByteWriter& w) const override;

private:
    double r(double t) const { return m_r0 + (m_r1 - m_r0) * t; }
    Vec3 m_base;
    AzimuthFrame m_frame;
    double m_length;  // |axis|
    double m_r0, m_r1;
    AngleRange m_angles;
};

// Reads the keys a cylinder and a cone share (base, axis, radius, facing, angles_deg), and a
// cone's top_radius; for the two types' readers.
std::shared_ptr<const Surface> read_frustum(YamlMap& m, bool cone);

}  // namespace radiosa
