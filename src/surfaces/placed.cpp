#include "surfaces/placed.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace radiosa {

PlacedSurface::PlacedSurface(std::shared_ptr<const Surface> inner, const Similarity& xf, bool back)
    : m_inner(std::move(inner)), m_xf(xf), m_back(back) {
    // (s R a) x (s R b) = s^2 R (a x b) for a rotation R: the inner orientation carries over.
    m_orientation = m_inner->orientation() * (back ? -1.0 : 1.0);
}

void PlacedSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    Vec3 a, b;
    m_inner->partials(s, t, &a, &b);
    *dPds = m_xf.scale * (m_xf.rotate * a);
    *dPdt = m_xf.scale * (m_xf.rotate * b);
}

std::optional<SurfaceHit> PlacedSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                   HitSide side) const {
    // The same ray in the inner surface's space has the same parameter along it.
    const Mat3 inv = glm::transpose(m_xf.rotate) / m_xf.scale;
    const Ray local{inv * (ray.origin - m_xf.translate), inv * ray.dir};
    if (!m_back) return m_inner->intersect(local, t_min, t_max, side);
    // The back side's front hits are the inner surface's back hits: step past front ones.
    for (int guard = 0; guard < 64; ++guard) {
        auto h = m_inner->intersect(local, t_min, t_max, HitSide::Any);
        if (!h) return std::nullopt;
        h->front = !h->front;
        if (side == HitSide::Any || h->front) return h;
        t_min = h->dist;
    }
    return std::nullopt;
}

double PlacedSurface::area(double s0, double s1, double t0, double t1) const {
    return m_xf.scale * m_xf.scale * m_inner->area(s0, s1, t0, t1);
}

BoundingSphere PlacedSurface::bound(double s0, double s1, double t0, double t1) const {
    const BoundingSphere b = m_inner->bound(s0, s1, t0, t1);
    return {m_xf.apply(b.center), m_xf.scale * b.radius};
}

std::pair<double, double> PlacedSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                      double t1) const {
    // a . (T + s R y) = a . T + (s R^T a) . y
    const auto [lo, hi] =
        m_inner->linear_range(m_xf.scale * (glm::transpose(m_xf.rotate) * a), s0, s1, t0, t1);
    const double c = glm::dot(a, m_xf.translate);
    return {c + lo, c + hi};
}

std::optional<Plane> PlacedSurface::plane() const {
    auto p = m_inner->plane();
    if (!p) return std::nullopt;
    const Vec3 n = m_xf.rotate * p->normal;
    const double sign = m_back ? -1.0 : 1.0;
    return Plane{sign * n, sign * (m_xf.scale * p->offset + glm::dot(n, m_xf.translate))};
}

std::optional<BoundingSphere> PlacedSurface::sphere() const {
    auto b = m_inner->sphere();
    if (!b) return std::nullopt;
    return BoundingSphere{m_xf.apply(b->center), m_xf.scale * b->radius};
}

bool PlacedSurface::patch_contour(double s0, double s1, double t0, double t1,
                                  std::vector<ContourPiece>* out) const {
    if (!m_inner->patch_contour(s0, s1, t0, t1, out)) return false;
    for (ContourPiece& c : *out) {
        c.a = m_xf.apply(c.a);
        c.b = m_xf.apply(c.b);
        c.center = m_xf.apply(c.center);
        c.e1 = m_xf.rotate * c.e1;
        c.e2 = m_xf.rotate * c.e2;
        c.radius *= m_xf.scale;
        for (Vec3& q : c.q) q = m_xf.apply(q);
        if (m_back) {
            std::swap(c.a, c.b);
            std::swap(c.from, c.to);
            std::reverse(c.q.begin(), c.q.end());
        }
    }
    if (m_back) std::reverse(out->begin(), out->end());
    return true;
}

int PlacedSurface::seen_once_from(std::span<const Vec3> from, double s0, double s1, double t0,
                                  double t1) const {
    // Culling asks this of every pair with a curved surface: no allocation. A polygon has at
    // most a handful of corners; more points than the buffer are left unproven.
    std::array<Vec3, 8> inner;
    if (from.size() > inner.size()) return 0;
    const Mat3 inv = glm::transpose(m_xf.rotate);
    for (std::size_t k = 0; k < from.size(); ++k) inner[k] = inv * (from[k] - m_xf.translate) / m_xf.scale;
    return (m_back ? -1 : 1) *
           m_inner->seen_once_from(std::span<const Vec3>(inner.data(), from.size()), s0, s1, t0, t1);
}

std::optional<ConvexSolid> PlacedSurface::convex_solid() const {
    auto c = m_inner->convex_solid();
    if (!c) return std::nullopt;
    c->center = m_xf.apply(c->center);
    c->axis = m_xf.rotate * c->axis;
    c->radius *= m_xf.scale;
    return c;
}

std::optional<FlatDisk> PlacedSurface::flat_disk() const {
    auto d = m_inner->flat_disk();
    if (!d) return std::nullopt;
    d->center = m_xf.apply(d->center);
    d->normal = (m_back ? -1.0 : 1.0) * (m_xf.rotate * d->normal);
    d->radius *= m_xf.scale;
    d->inner_radius *= m_xf.scale;
    return d;
}

std::optional<RoundFrustum> PlacedSurface::round_frustum() const {
    auto t = m_inner->round_frustum();
    if (!t) return std::nullopt;
    t->base = m_xf.apply(t->base);
    t->axis = m_xf.rotate * t->axis;
    t->length *= m_xf.scale;
    t->radius *= m_xf.scale;
    t->top_radius *= m_xf.scale;
    return t;
}

std::optional<SphericalCap> PlacedSurface::spherical_cap() const {
    auto c = m_inner->spherical_cap();
    if (!c) return std::nullopt;
    c->center = m_xf.apply(c->center);
    c->axis = m_xf.rotate * c->axis;
    c->radius *= m_xf.scale;
    c->height *= m_xf.scale;
    return c;
}

void PlacedSurface::write_key(ByteWriter& w) const {
    m_inner->write_key(w);
    w.f64(m_xf.scale);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) w.f64(m_xf.rotate[c][r]);
    for (int k = 0; k < 3; ++k) w.f64(m_xf.translate[k]);
    w.u8(m_back ? 1 : 0);
}

Mat3 rotation_deg(const Vec3& axis, double angle_deg) {
    // R = cos I + sin [u]x + (1 - cos) u u^T, column by column.
    const Vec3 u = axis / glm::length(axis);
    const double angle = deg_to_rad(angle_deg);
    const double c = std::cos(angle), s = std::sin(angle);
    Mat3 r(1.0);
    for (int j = 0; j < 3; ++j) {
        Vec3 e(0.0);
        e[j] = 1.0;
        r[j] = c * e + s * glm::cross(u, e) + (1.0 - c) * glm::dot(u, e) * u;
    }
    return r;
}

Similarity compose(const Similarity& outer, const Similarity& inner) {
    if (inner.identity()) return outer;
    if (outer.identity()) return inner;
    return {outer.scale * inner.scale, outer.rotate * inner.rotate,
            outer.translate + outer.scale * (outer.rotate * inner.translate)};
}

Similarity read_transform(const YAML::Node& node, const std::string& file) {
    YamlMap m(node, file, "transform");
    Similarity xf;
    if (auto s = m.optional("scale")) {
        xf.scale = yaml_number(*s, file, "scale");
        if (!(xf.scale >= 1e-9 && xf.scale <= 1e9))
            throw Error(loc_of(*s, file),
                        "transform scale must be a uniform scale in [1e-9, 1e9], got " + s->Scalar());
    }
    if (auto r = m.optional("rotate_deg")) {
        YamlMap rm(*r, file, "rotate_deg");
        const YAML::Node an = rm.required("axis");
        const Vec3 axis = yaml_vec3(an, file, "axis");
        const double len = glm::length(axis);
        if (!(len > 0.0) || !std::isfinite(len))
            throw Error(loc_of(an, file), "rotate_deg axis must be a non-zero vector [x, y, z]");
        const double angle = rm.number("angle");
        rm.reject_unknown_keys("axis, angle");
        xf.rotate = rotation_deg(axis, angle);
    }
    if (m.has("translate")) xf.translate = m.vec3("translate");
    m.reject_unknown_keys("scale, rotate_deg, translate");
    return xf;
}

}  // namespace radiosa
