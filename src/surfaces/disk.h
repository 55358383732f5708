#pragma once
// The `disk` surface type: a flat disk, annulus or sector of either, front on its normal's side.
#include "surfaces/revolution.h"
#include "surfaces/surface.h"

namespace radiosa {

// P(s, t) = center + rho(t) radial(phi(s)): phi over the angle range, rho from the inner radius
// (t = 0) to the radius (t = 1), linear in t.
class DiskSurface final : public Surface {
public:
    DiskSurface(const Vec3& center, const Vec3& unit_normal, double radius, double inner_radius,
                const AngleRange& angles);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    double area(double s0, double s1, double t0, double t1) const override;
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    // Exact: a . P is a . center + rho (A cos phi + B sin phi), rho >= 0.
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    std::optional<Plane> plane() const override {
        return Plane{m_frame.axis, glm::dot(m_frame.axis, m_center)};
    }
    std::optional<FlatDisk> flat_disk() const override {
        if (!m_angles.full()) return std::nullopt;
        return FlatDisk{m_center, m_frame.axis, m_radius, m_inner};
    }
    bool chords_never_cross() const override { return true; }
    bool front_segments_escape() const override { return true; }
    bool sees_itself() const override { return false; }
    bool back_segments_escape() const override { return true; }
    bool back_sees_itself() const override { return false; }
    bool patch_contour(double s0, double s1, double t0, double t1,
                       std::vector<ContourPiece>* out) const override;
    // Exact when the line is the disk's own axis (the rectangle's outer radius).
    double max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                  double t1) const override;
    // Exact when p is on the disk's axis.
    double max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const override;
    bool faces_ball(double s0, double s1, double t0, double t1, const BoundingSphere& b,
                    bool back) const override;
    bool wraps_in_s() const override { return m_angles.full(); }
    bool pole_at_t0() const override { return m_inner == 0.0; }
    void write_key(ByteWriter& w) const override;

private:
    double rho(double t) const { return m_inner + (m_radius - m_inner) * t; }
    Vec3 m_center;
    AzimuthFrame m_frame;
    double m_radius, m_inner;
    AngleRange m_angles;
};

}  // namespace radiosa
