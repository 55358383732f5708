#include "geometry/intersections.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "geometry/scene_geometry.h"
#include "util/convex_distance.h"

namespace radiosa {

namespace {

// The shape of a surface as far as this check knows it.
struct Shape {
    std::optional<std::array<Vec3, 4>> polygon;  // a planar convex quad
    std::optional<BoundingSphere> sphere;        // a whole sphere
};

Shape shape_of(const Surface& s) {
    Shape sh;
    if (s.plane() && s.patches_are_polygons())
        sh.polygon = std::array<Vec3, 4>{s.point(0, 0), s.point(1, 0), s.point(1, 1), s.point(0, 1)};
    else if (s.sphere() && s.whole_sphere())
        sh.sphere = s.sphere();
    return sh;
}

Vec3 normal_of(const std::array<Vec3, 4>& v) {
    Vec3 m(0.0);
    for (int k = 0; k < 4; ++k) m += glm::cross(v[k], v[(k + 1) % 4]);
    return glm::normalize(m);
}

// The open interval, along the line `dir`, where the polygon's interior crosses the plane
// (n, o): empty unless the polygon has corners strictly on both sides.
std::optional<std::pair<double, double>> crossing(const std::array<Vec3, 4>& v, const Vec3& n, const Vec3& o,
                                                  const Vec3& dir, double eps) {
    std::array<double, 4> d;
    bool above = false, below = false;
    for (int k = 0; k < 4; ++k) {
        d[k] = glm::dot(n, v[k] - o);
        above = above || d[k] > eps;
        below = below || d[k] < -eps;
    }
    if (!above || !below) return std::nullopt;
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 4; ++k) {
        const int l = (k + 1) % 4;
        const bool spans = (d[k] <= 0.0 && d[l] >= 0.0) || (d[k] >= 0.0 && d[l] <= 0.0);
        if (!spans || d[k] == d[l]) continue;
        const Vec3 p = v[k] + (v[l] - v[k]) * (d[k] / (d[k] - d[l]));
        const double u = glm::dot(p, dir);
        lo = std::min(lo, u);
        hi = std::max(hi, u);
    }
    return std::make_pair(lo, hi);
}

bool polygons_cross(const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b, double eps) {
    const Vec3 na = normal_of(a), nb = normal_of(b);
    const Vec3 dir = glm::cross(na, nb);
    const double len = glm::length(dir);
    if (len < 1e-12) return false;  // parallel or coplanar: not a crossing (coplanar overlap is not checked)
    const auto ia = crossing(a, nb, b[0], dir / len, eps), ib = crossing(b, na, a[0], dir / len, eps);
    if (!ia || !ib) return false;
    return std::min(ia->second, ib->second) - std::max(ia->first, ib->first) > eps;
}

bool sphere_crosses_polygon(const BoundingSphere& s, const std::array<Vec3, 4>& v, double eps) {
    const double nearest = distance_to_polygon(s.center, v);
    double farthest = 0.0;
    for (const Vec3& c : v) farthest = std::max(farthest, glm::length(c - s.center));
    return nearest < s.radius - eps && farthest > s.radius + eps;
}

bool spheres_cross(const BoundingSphere& a, const BoundingSphere& b, double eps) {
    const double d = glm::length(a.center - b.center);
    return d < a.radius + b.radius - eps && d > std::abs(a.radius - b.radius) + eps;
}

// Whether a chord between neighbouring points of a's kSamples x kSamples grid (along s or
// along t) crosses b strictly inside both: at least `margin` of the chord from its ends, and
// b's parameters at least 1e-6 from an edge that is not a seam.
constexpr int kSamples = 33;

bool inside_parameters(const Surface& b, const SurfaceHit& h) {
    constexpr double d = 1e-6;
    const auto in = [&](double x, bool wraps) { return wraps || (x > d && x < 1.0 - d); };
    return in(h.s, b.wraps_in_s()) && in(h.t, b.wraps_in_t());
}

// The chord passes from one side of b to the other there (its ends on either side of b's
// tangent plane by more than eps), rather than touching it (a ring resting on a floor).
bool transversal(const Surface& b, const SurfaceHit& h, const Vec3& x, const Vec3& p0, const Vec3& p1,
                 double eps) {
    const Vec3 n = b.normal(h.s, h.t);
    const double len = glm::length(n);
    if (!(len > 0.0)) return false;  // a pole or collapsed edge: no tangent plane to cross
    const double d0 = glm::dot(p0 - x, n) / len, d1 = glm::dot(p1 - x, n) / len;
    return d0 * d1 < 0.0 && std::min(std::abs(d0), std::abs(d1)) > eps;
}

bool chord_crosses(const Surface& b, const Vec3& p0, const Vec3& p1, double eps) {
    const double len = glm::length(p1 - p0);
    if (!(len > eps)) return false;  // a collapsed edge or pole
    const Ray ray{p0, (p1 - p0) / len};
    const double margin = std::max(1e-7 * len, eps);
    double from = margin;
    for (int k = 0; k < 8 && from < len - margin; ++k) {  // past hits on b's edges, a few more
        const auto h = b.intersect(ray, from, len - margin, HitSide::Any);
        if (!h) return false;
        if (inside_parameters(b, *h) && transversal(b, *h, ray.at(h->dist), p0, p1, eps)) return true;
        from = h->dist + margin;
    }
    return false;
}

// a's kSamples x kSamples points, row j (t = j / (kSamples - 1)) after row j - 1.
std::vector<Vec3> sample_grid(const Surface& a) {
    constexpr double step = 1.0 / (kSamples - 1);
    std::vector<Vec3> grid(kSamples * kSamples);
    for (int j = 0; j < kSamples; ++j)
        for (int i = 0; i < kSamples; ++i) grid[j * kSamples + i] = a.point(i * step, j * step);
    return grid;
}

// Whether a chord of the grid, along s or along t, crosses b.
bool chords_cross(const std::vector<Vec3>& grid, const Surface& b, double eps) {
    for (int j = 0; j < kSamples; ++j)
        for (int i = 0; i + 1 < kSamples; ++i)
            if (chord_crosses(b, grid[j * kSamples + i], grid[j * kSamples + i + 1], eps) ||
                chord_crosses(b, grid[i * kSamples + j], grid[(i + 1) * kSamples + j], eps))
                return true;
    return false;
}

// The sampled check of surfaces a and b; grid(k) is surface k's sample_grid, made once.
template <class Grid>
bool sampled_cross(const SceneGeometry& g, int a, int b, double eps, Grid&& grid) {
    if (g.entry(a) >= 0 && g.entry(a) == g.entry(b)) return false;  // parts or sides of one entry
    const BoundingSphere &ba = g.surface_bound(a), &bb = g.surface_bound(b);
    if (glm::length(ba.center - bb.center) > ba.radius + bb.radius + eps) return false;
    return chords_cross(grid(a), g.surface(b), eps) || chords_cross(grid(b), g.surface(a), eps);
}

}  // namespace

std::vector<SurfaceIntersection> find_intersections(const SceneGeometry& g) {
    std::vector<SurfaceIntersection> out;
    const double eps = 1e-9 * g.scale();
    std::vector<Shape> shapes;
    for (int k = 0; k < g.surface_count(); ++k) shapes.push_back(shape_of(g.surface(k)));
    std::vector<std::vector<Vec3>> grids(static_cast<std::size_t>(g.surface_count()));
    const auto grid = [&](int k) -> const std::vector<Vec3>& {
        std::vector<Vec3>& points = grids[static_cast<std::size_t>(k)];
        if (points.empty()) points = sample_grid(g.surface(k));
        return points;
    };
    for (int a = 0; a < g.surface_count(); ++a)
        for (int b = a + 1; b < g.surface_count(); ++b) {
            const Shape &sa = shapes[a], &sb = shapes[b];
            bool cross = false;
            if (sa.polygon && sb.polygon)
                cross = polygons_cross(*sa.polygon, *sb.polygon, eps);
            else if (sa.sphere && sb.polygon)
                cross = sphere_crosses_polygon(*sa.sphere, *sb.polygon, eps);
            else if (sa.polygon && sb.sphere)
                cross = sphere_crosses_polygon(*sb.sphere, *sa.polygon, eps);
            else if (sa.sphere && sb.sphere)
                cross = spheres_cross(*sa.sphere, *sb.sphere, eps);
            else
                cross = sampled_cross(g, a, b, eps, grid);
            if (cross) out.push_back({a, b});
        }
    return out;
}

std::string intersection_names(const SceneGeometry& g, const std::vector<SurfaceIntersection>& found) {
    std::string names;
    for (const SurfaceIntersection& x : found)
        names += fmt::format("{}'{}' and '{}'", names.empty() ? "" : ", ", g.surface_name(x.a),
                             g.surface_name(x.b));
    return names;
}

std::string intersection_warning(const SceneGeometry& g, const std::vector<SurfaceIntersection>& found) {
    return fmt::format(
        "surfaces intersect: {}. The parts of one inside the other still exchange light through it, so "
        "closure and the energy balance are not to be trusted and light leaks into the image; move the "
        "surfaces apart (touching along an edge is fine), or add --strict to refuse such scenes",
        intersection_names(g, found));
}

}  // namespace radiosa
