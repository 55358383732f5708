#pragma once
// Visibility and horizon events: where the inner form factor toward a polygon, as a function of
// the outer point, stops being smooth (formfactor/form_factor.cpp checks regions they cross).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "formfactor/cubature.h"
#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

// Where, as a function of the outer point x, the inner form factor toward a polygon stops being
// smooth: x's horizon passing a vertex of the polygon (curved outer patches), and a blocking
// sphere's outline touching an edge's great circle (x on a plane through the edge tangent to
// the sphere) or passing a vertex (x on the cone from the vertex tangent to the sphere). Each is
// the zero set of a signed function; a region whose sample points see different signs holds one.
class EventSet {
public:
    void add_horizons(const std::array<Vec3, 4>& v) {
        for (const Vec3& p : v) m_horizons.push_back(p);
    }
    void add_sphere(const std::array<Vec3, 4>& v, const BoundingSphere& b) {
        for (int k = 0; k < 4; ++k) {
            const Vec3 &p = v[k], &q = v[(k + 1) % 4];
            const Vec3 u = glm::normalize(q - p);
            const Vec3 w = (b.center - p) - glm::dot(b.center - p, u) * u;
            const double d = glm::length(w);
            if (d > b.radius) {
                const double alpha = b.radius / d, beta = std::sqrt(1.0 - alpha * alpha);
                const Vec3 wh = w / d, m = glm::cross(u, wh);
                m_planes.push_back({alpha * wh + beta * m, p});
                m_planes.push_back({alpha * wh - beta * m, p});
            }
            const Vec3 to_c = b.center - p;
            const double l2 = glm::dot(to_c, to_c);
            if (l2 > b.radius * b.radius)
                m_cones.push_back({p, to_c / std::sqrt(l2), 1.0 - b.radius * b.radius / l2});
        }
    }
    // Flat occluders: x on a plane through an edge of one polygon and a vertex of another (the
    // target or another occluder), where a shadow's edge meets a corner.
    void add_flats(const std::array<Vec3, 4>& v, const std::vector<std::array<Vec3, 4>>& occ) {
        auto edges_vertices = [&](const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b) {
            for (int k = 0; k < 4; ++k)
                for (const Vec3& w : b) {
                    const Vec3 nrm = glm::cross(a[(k + 1) % 4] - a[k], w - a[k]);
                    if (glm::length(nrm) > 0.0) m_planes.push_back({nrm, a[k]});
                }
        };
        for (std::size_t k = 0; k < occ.size(); ++k) {
            edges_vertices(occ[k], v);
            edges_vertices(v, occ[k]);
            for (std::size_t l = 0; l < occ.size(); ++l)
                if (l != k) edges_vertices(occ[k], occ[l]);
        }
    }
    bool empty() const { return m_horizons.empty() && m_planes.empty() && m_cones.empty(); }

    // Does an event cross the region? Signs at a 3 x 3 grid of its points.
    bool crosses(const Surface& si, const Rect& r) const {
        if (empty()) return false;
        const std::size_t n = m_horizons.size() + m_planes.size() + m_cones.size();
        std::vector<signed char> sign(n, 0), mixed(n, 0);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
                const double s = r.s0 + 0.5 * a * (r.s1 - r.s0), t = r.t0 + 0.5 * b * (r.t1 - r.t0);
                const Vec3 x = si.point(s, t);
                std::size_t k = 0;
                auto note = [&](double e) {
                    const signed char sg = e > 0.0 ? 1 : (e < 0.0 ? -1 : 0);
                    if (a + b == 0)
                        sign[k] = sg;
                    else if (sg != sign[k])
                        mixed[k] = 1;
                    ++k;
                };
                if (!m_horizons.empty()) {
                    const Vec3 nx = si.normal(s, t);
                    for (const Vec3& v : m_horizons) note(glm::dot(nx, v - x));
                }
                for (const auto& [nrm, p] : m_planes) note(glm::dot(nrm, x - p));
                for (const Cone& c : m_cones) {
                    const Vec3 d = x - c.apex;
                    const double along = glm::dot(d, c.axis);
                    note(along > 0.0 ? along * along - c.cos2 * glm::dot(d, d) : -1.0);
                }
            }
        return std::any_of(mixed.begin(), mixed.end(), [](signed char m) { return m != 0; });
    }

private:
    struct Cone {
        Vec3 apex, axis;
        double cos2;
    };
    std::vector<Vec3> m_horizons;
    std::vector<std::pair<Vec3, Vec3>> m_planes;  // normal, point
    std::vector<Cone> m_cones;
};

}  // namespace radiosa
