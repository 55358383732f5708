#include "surfaces/quad.h"

#include <algorithm>
#include <cmath>

#include "surfaces/registry.h"

namespace radiosa {

namespace {
double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }
}  // namespace

QuadSurface::QuadSurface(const Vec3& c0, const Vec3& c1, const Vec3& c2, const Vec3& c3)
    : m_corners{c0, c1, c2, c3}, m_p0(c0), m_e(c1 - c0), m_f(c3 - c0), m_g(c0 - c1 + c2 - c3) {
    // The scene reader has checked planarity and convexity; the diagonals' cross product
    // gives the plane normal robustly for any convex quad.
    const Vec3 n = glm::normalize(glm::cross(c2 - c0, c3 - c1));
    m_plane = Plane{n, glm::dot(n, 0.25 * (c0 + c1 + c2 + c3))};
    m_u = glm::normalize(m_e);
    m_v = glm::cross(n, m_u);
    m_ex = glm::dot(m_e, m_u), m_ey = glm::dot(m_e, m_v);
    m_fx = glm::dot(m_f, m_u), m_fy = glm::dot(m_f, m_v);
    m_gx = glm::dot(m_g, m_u), m_gy = glm::dot(m_g, m_v);
    m_k2 = cross2(m_gx, m_gy, m_fx, m_fy);
    m_exf = cross2(m_ex, m_ey, m_fx, m_fy);
}

Vec3 QuadSurface::point(double s, double t) const { return m_p0 + s * m_e + t * m_f + s * t * m_g; }

std::pair<double, double> QuadSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                    double t1) const {
    const double v[4] = {glm::dot(a, point(s0, t0)), glm::dot(a, point(s1, t0)), glm::dot(a, point(s0, t1)),
                         glm::dot(a, point(s1, t1))};
    return {std::min({v[0], v[1], v[2], v[3]}), std::max({v[0], v[1], v[2], v[3]})};
}

void QuadSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    *dPds = m_e + t * m_g;
    *dPdt = m_f + s * m_g;
}

std::optional<std::pair<double, double>> QuadSurface::invert(const Vec3& x) const {
    // Solve q = s e + t f + s t g in plane coordinates: eliminating s gives
    // k2 t^2 + k1 t + k0 = 0 with k2 = g x f, k1 = q x g + e x f, k0 = q x e.
    const Vec3 q3 = x - m_p0;
    const double qx = glm::dot(q3, m_u), qy = glm::dot(q3, m_v);
    const double ex = m_ex, ey = m_ey, fx = m_fx, fy = m_fy, gx = m_gx, gy = m_gy;
    const double k2 = m_k2;
    const double k1 = cross2(qx, qy, gx, gy) + m_exf;
    const double k0 = cross2(qx, qy, ex, ey);
    const double scale = std::abs(m_exf);
    constexpr double kEdge = 1e-12;  // accept points on the boundary despite rounding

    auto finish = [&](double t) -> std::optional<std::pair<double, double>> {
        if (!(t >= -kEdge && t <= 1.0 + kEdge)) return std::nullopt;
        const double dx = ex + t * gx, dy = ey + t * gy;
        const double s = ((qx - t * fx) * dx + (qy - t * fy) * dy) / (dx * dx + dy * dy);
        if (!(s >= -kEdge && s <= 1.0 + kEdge)) return std::nullopt;
        return std::make_pair(std::clamp(s, 0.0, 1.0), std::clamp(t, 0.0, 1.0));
    };

    if (std::abs(k2) <= 1e-14 * scale) {  // parallelogram: the map is affine
        if (k1 == 0.0) return std::nullopt;
        return finish(-k0 / k1);
    }
    double disc = k1 * k1 - 4.0 * k2 * k0;
    if (disc < 0.0) {
        if (disc < -1e-12 * k1 * k1) return std::nullopt;
        disc = 0.0;
    }
    const double root = std::sqrt(disc);
    const double qq = -0.5 * (k1 + std::copysign(root, k1));
    const double t1 = qq / k2;
    const double t2 = qq != 0.0 ? k0 / qq : t1;
    if (auto r = finish(t1)) return r;
    return finish(t2);
}

std::optional<SurfaceHit> QuadSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                 HitSide side) const {
    const double denom = glm::dot(m_plane.normal, ray.dir);
    if (denom == 0.0) return std::nullopt;  // parallel: a grazing ray sees no area
    const bool front = denom < 0.0;
    if (side == HitSide::FrontOnly && !front) return std::nullopt;
    const double dist = (m_plane.offset - glm::dot(m_plane.normal, ray.origin)) / denom;
    if (!(dist > t_min && dist < t_max)) return std::nullopt;
    const auto st = invert(ray.at(dist));
    if (!st) return std::nullopt;
    return SurfaceHit{dist, st->first, st->second, front};
}

double QuadSurface::area(double s0, double s1, double t0, double t1) const {
    // For a planar bilinear map |dP/ds x dP/dt| = n . (e x f + s e x g + t g x f) is affine
    // in (s, t), so its mean over the rectangle is its value at the centre.
    const double sm = 0.5 * (s0 + s1), tm = 0.5 * (t0 + t1);
    const Vec3 j = glm::cross(m_e, m_f) + sm * glm::cross(m_e, m_g) + tm * glm::cross(m_g, m_f);
    return std::abs(glm::dot(j, m_plane.normal)) * (s1 - s0) * (t1 - t0);
}

BoundingSphere QuadSurface::bound(double s0, double s1, double t0, double t1) const {
    // A planar convex quad lies inside the sphere around its corners' centroid that
    // reaches its farthest corner (isoparametric lines of a bilinear quad are straight).
    const Vec3 c[4] = {point(s0, t0), point(s1, t0), point(s1, t1), point(s0, t1)};
    const Vec3 mid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
    double r = 0.0;
    for (const auto& p : c) r = std::max(r, glm::length(p - mid));
    return {mid, r};
}

double QuadSurface::max_distance_from_line(const Vec3& p, const Vec3& u, double s0, double s1, double t0,
                                           double t1) const {
    double d = 0.0;
    for (const Vec3& c : {point(s0, t0), point(s1, t0), point(s1, t1), point(s0, t1)}) {
        const Vec3 q = c - p;
        d = std::max(d, glm::length(q - glm::dot(q, u) * u));
    }
    return d;
}

double QuadSurface::max_distance_from_point(const Vec3& p, double s0, double s1, double t0, double t1) const {
    return std::max({glm::length(point(s0, t0) - p), glm::length(point(s1, t0) - p),
                     glm::length(point(s1, t1) - p), glm::length(point(s0, t1) - p)});
}

void QuadSurface::write_key(ByteWriter& w) const {
    for (const Vec3& c : m_corners)
        for (int k = 0; k < 3; ++k) w.f64(c[k]);
}

namespace {

// A quad must be planar and strictly convex, or its bilinear map folds over itself.
void validate_quad(const std::array<Vec3, 4>& c, const std::string& name, const FileLoc& where) {
    double size = 0.0;
    for (int k = 0; k < 4; ++k) size = std::max(size, glm::length(c[(k + 1) % 4] - c[k]));
    if (!(size > 0.0)) throw Error(where, "quad '" + name + "' is degenerate: all corners coincide");
    // The plane normal from the corner with the strongest turn: the diagonals' cross product
    // would vanish for a crossed (bow-tie) quad and misreport it as collinear.
    Vec3 n(0.0);
    for (int k = 0; k < 4; ++k) {
        const Vec3 nk = glm::cross(c[(k + 1) % 4] - c[k], c[(k + 3) % 4] - c[k]);
        if (glm::length(nk) > glm::length(n)) n = nk;
    }
    const double nlen = glm::length(n);
    if (nlen <= 1e-12 * size * size)
        throw Error(where, "quad '" + name + "' is degenerate: its corners are collinear");
    const Vec3 u = n / nlen;
    const Vec3 mid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
    for (int k = 0; k < 4; ++k)
        if (std::abs(glm::dot(c[k] - mid, u)) > 1e-9 * size)
            throw Error(where, "quad '" + name + "' is not planar: corner " + std::to_string(k) +
                                   " is off the plane of the others (split it into planar quads)");
    for (int k = 0; k < 4; ++k) {
        const Vec3 a = c[(k + 1) % 4] - c[k];
        const Vec3 b = c[(k + 3) % 4] - c[k];
        if (glm::dot(glm::cross(a, b), u) <= 1e-9 * size * size)
            throw Error(where, "quad '" + name + "' is degenerate or not convex at corner " +
                                   std::to_string(k) + " (list the corners in order around the quad)");
    }
}

// corners: [[x,y,z] x 4], in order around the quad: P(0,0), P(1,0), P(1,1), P(0,1); or
// origin + edge_s + edge_t (a parallelogram). The front side is the one (c1 - c0) x (c3 - c0)
// points to.
std::shared_ptr<const Surface> read_quad(YamlMap& m, const std::string& name) {
    std::array<Vec3, 4> c;
    const bool edges = m.has("origin") || m.has("edge_s") || m.has("edge_t");
    if (m.has("corners")) {
        if (edges)
            throw Error(m.key_loc("corners"),
                        "quad '" + name + "': give either corners or origin + edge_s + edge_t, not both");
        const YAML::Node list = m.required("corners");
        if (!list.IsSequence() || list.size() != 4)
            throw Error(loc_of(list, m.file()), "corners must be a list of 4 points [[x,y,z], ...]");
        for (int k = 0; k < 4; ++k) c[k] = yaml_vec3(list[k], m.file(), "corners[" + std::to_string(k) + "]");
    } else if (edges) {
        const Vec3 o = m.vec3("origin");
        const Vec3 es = m.vec3("edge_s");
        const Vec3 et = m.vec3("edge_t");
        c = {o, o + es, o + es + et, o + et};
    } else {
        throw Error(m.loc(), "quad '" + name + "' needs corners, or origin + edge_s + edge_t");
    }
    validate_quad(c, name, m.loc());
    return std::make_shared<QuadSurface>(c[0], c[1], c[2], c[3]);
}

}  // namespace

extern const SurfaceType kQuadType;
const SurfaceType kQuadType = {
    .name = "quad",
    .key_id = 0,
    .keys = "corners | origin + edge_s + edge_t",
    .read = read_quad,
    .example = {{"corners", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]"}},
    .variants = {{"corners", "[[-0.5, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]"},
                 {"corners", "[[0, 0, 0], [1.5, 0, 0], [1, 1, 0], [0, 1, 0]]"},
                 {"corners", "[[0, 0, 0], [1, 0, 0], [1.5, 1.5, 0], [0, 1, 0]]"},
                 {"corners", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1.5, 0]]"},
                 {"corners", "[[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]"},
                 {"corners", "[[0, 1, 0], [1, 1, 0], [1, 0, 0], [0, 0, 0]]"}},
};

}  // namespace radiosa
