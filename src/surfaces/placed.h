#pragma once
// A surface placed by a `transform` (uniform scale, rotation about an axis, translation, in that
// order), or the back side of a two-sided surface, or both. Any type can be placed: the wrapper
// maps points, partials, rays, bounds and planes exactly, so nothing is approximated.
#include <memory>

#include "surfaces/surface.h"
#include "util/yaml_reader.h"

namespace radiosa {

// x -> translate + scale * rotate * x.
struct Similarity {
    double scale = 1.0;
    Mat3 rotate{1.0};
    Vec3 translate{0.0};
    Vec3 apply(const Vec3& x) const { return translate + scale * (rotate * x); }
    bool identity() const { return scale == 1.0 && rotate == Mat3(1.0) && translate == Vec3(0.0); }
    bool operator==(const Similarity&) const = default;
};

// The rotation by angle_deg degrees about the axis (non-zero; normalised here), right-handed:
// Rodrigues' formula, the one every transform and motion uses (so equal inputs give equal bits).
Mat3 rotation_deg(const Vec3& axis, double angle_deg);

// x -> outer(inner(x)). Exact when either is the identity: an unplaced surface moved by a motion
// is placed by that motion's bits.
Similarity compose(const Similarity& outer, const Similarity& inner);

class PlacedSurface final : public Surface {
public:
    // back: the side opposite the inner surface's front becomes this surface's front.
    PlacedSurface(std::shared_ptr<const Surface> inner, const Similarity& xf, bool back);
    Vec3 point(double s, double t) const override { return m_xf.apply(m_inner->point(s, t)); }
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    // The back side's hits are the inner surface's, seen from the other side: the same points.
    bool blocks(const Ray& ray, double t_min, double t_max) const override {
        const Mat3 inv = glm::transpose(m_xf.rotate) / m_xf.scale;
        return m_inner->blocks(Ray{inv * (ray.origin - m_xf.translate), inv * ray.dir}, t_min, t_max);
    }
    double area(double s0, double s1, double t0, double t1) const override;
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    std::optional<Plane> plane() const override;
    bool patches_are_polygons() const override { return m_inner->patches_are_polygons(); }
    std::optional<BoundingSphere> sphere() const override;
    Mat3 sphere_axes() const override { return m_xf.rotate * m_inner->sphere_axes(); }
    std::pair<double, double> sphere_angles(double s, double t) const override {
        return m_inner->sphere_angles(s, t);
    }
    bool whole_sphere() const override { return m_inner->whole_sphere(); }
    bool chords_never_cross() const override { return m_inner->chords_never_cross(); }
    bool front_segments_escape() const override {
        return m_back ? m_inner->back_segments_escape() : m_inner->front_segments_escape();
    }
    bool sees_itself() const override {
        return m_back ? m_inner->back_sees_itself() : m_inner->sees_itself();
    }
    bool back_segments_escape() const override {
        return m_back ? m_inner->front_segments_escape() : m_inner->back_segments_escape();
    }
    bool back_sees_itself() const override {
        return m_back ? m_inner->sees_itself() : m_inner->back_sees_itself();
    }
    bool patch_contour(double s0, double s1, double t0, double t1,
                       std::vector<ContourPiece>* out) const override;
    // The points taken into the inner surface's frame; the side flips on the back.
    int seen_once_from(std::span<const Vec3> from, double s0, double s1, double t0, double t1) const override;
    std::optional<ConvexSolid> convex_solid() const override;
    std::optional<FlatDisk> flat_disk() const override;
    std::optional<RoundFrustum> round_frustum() const override;
    std::optional<SphericalCap> spherical_cap() const override;
    double max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                  double t1) const override {
        const Mat3 inv = glm::transpose(m_xf.rotate);
        return m_xf.scale * m_inner->max_distance_from_line(inv * (p - m_xf.translate) / m_xf.scale, inv * u,
                                                            s0, s1, t0, t1);
    }
    double max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const override {
        const Mat3 inv = glm::transpose(m_xf.rotate);
        return m_xf.scale *
               m_inner->max_distance_from_point(inv * (p - m_xf.translate) / m_xf.scale, s0, s1, t0, t1);
    }
    bool faces_ball(double s0, double s1, double t0, double t1, const BoundingSphere& b,
                    bool back) const override {
        return m_inner->faces_ball(s0, s1, t0, t1, to_inner(b), back != m_back);
    }
    bool on_convex_hull(double s0, double s1, double t0, double t1) const override {
        return m_inner->on_convex_hull(s0, s1, t0, t1);
    }
    bool wraps_in_s() const override { return m_inner->wraps_in_s(); }
    bool wraps_in_t() const override { return m_inner->wraps_in_t(); }
    bool pole_at_t0() const override { return m_inner->pole_at_t0(); }
    bool pole_at_t1() const override { return m_inner->pole_at_t1(); }
    // The inner surface's key, then the transform and the side.
    void write_key(ByteWriter& w) const override;

private:
    BoundingSphere to_inner(const BoundingSphere& b) const {
        return {glm::transpose(m_xf.rotate) * (b.center - m_xf.translate) / m_xf.scale,
                b.radius / m_xf.scale};
    }
    std::shared_ptr<const Surface> m_inner;
    Similarity m_xf;
    bool m_back;
};

// transform: {scale: s > 0, rotate_deg: {axis: [x, y, z], angle: a}, translate: [x, y, z]},
// each optional. Bad values throw at their file:line:col.
Similarity read_transform(const YAML::Node& node, const std::string& file);

}  // namespace radiosa
