#include "geometry/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "geometry/ray_index.h"
#include "scene/scene.h"

namespace radiosa {

SceneGeometry::SceneGeometry(const Scene& scene) : m_index(std::make_shared<LazyIndex>()) {
    Vec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const auto& desc : scene.surfaces) {
        const int k = static_cast<int>(m_surfaces.size());
        m_surfaces.push_back(desc.shape);
        m_names.push_back(desc.name);
        m_ns.push_back(desc.ns);
        m_nt.push_back(desc.nt);
        m_twin.push_back(desc.twin);
        m_entry.push_back(desc.entry);
        m_first_patch.push_back(static_cast<int>(m_patches.size()));
        const Surface& surf = *m_surfaces.back();
        const bool polygon = surf.patches_are_polygons();
        for (int it = 0; it < desc.nt; ++it)
            for (int is = 0; is < desc.ns; ++is) {
                Patch p;
                p.surface = k;
                p.is = is;
                p.it = it;
                p.s0 = double(is) / desc.ns;
                p.s1 = double(is + 1) / desc.ns;
                p.t0 = double(it) / desc.nt;
                p.t1 = double(it + 1) / desc.nt;
                p.area = surf.area(p.s0, p.s1, p.t0, p.t1);
                p.bound = surf.bound(p.s0, p.s1, p.t0, p.t1);
                p.corners = {surf.point(p.s0, p.t0), surf.point(p.s1, p.t0), surf.point(p.s1, p.t1),
                             surf.point(p.s0, p.t1)};
                p.polygon = polygon;
                m_patches.push_back(p);
            }
        const BoundingSphere b = surf.bound(0, 1, 0, 1);
        m_surface_bounds.push_back(b);
        lo = glm::min(lo, b.center - Vec3(b.radius));
        hi = glm::max(hi, b.center + Vec3(b.radius));
    }
    m_scale = glm::length(hi - lo);
}

std::array<Vec3, 4> SceneGeometry::front_polygon(int patch) const {
    const Patch& p = m_patches[patch];
    return facing(p.corners, m_surfaces[p.surface]->normal(0.5 * (p.s0 + p.s1), 0.5 * (p.t0 + p.t1)));
}

std::array<Vec3, 4> SceneGeometry::facing(std::array<Vec3, 4> v, const Vec3& front) {
    const Vec3 newell = glm::cross(v[1] - v[0], v[3] - v[0]) + glm::cross(v[3] - v[2], v[1] - v[2]);
    if (glm::dot(front, newell) < 0.0) std::swap(v[1], v[3]);
    return v;
}

Hit SceneGeometry::locate(int k, double s, double t, double dist) const {
    Hit h;
    h.dist = dist;
    h.surface = k;
    h.s = s;
    h.t = t;
    const double fs = s * m_ns[k], ft = t * m_nt[k];
    const int is = std::clamp(static_cast<int>(fs), 0, m_ns[k] - 1);
    const int it = std::clamp(static_cast<int>(ft), 0, m_nt[k] - 1);
    h.u = std::clamp(fs - is, 0.0, 1.0);
    h.v = std::clamp(ft - it, 0.0, 1.0);
    h.patch = patch_index(k, is, it);
    return h;
}

struct SceneGeometry::LazyIndex {
    std::once_flag once;
    std::unique_ptr<RayIndex> index;
};

const RayIndex& SceneGeometry::index() const {
    std::call_once(m_index->once, [&] {
        std::vector<const Surface*> all;
        for (const auto& s : m_surfaces) all.push_back(s.get());
        m_index->index = std::make_unique<RayIndex>(all);
    });
    return *m_index->index;
}

std::optional<Hit> SceneGeometry::intersect_front(const Ray& ray) const {
    if (surface_count() < kRayIndexMinSurfaces) return intersect_front_by_loop(ray);
    const auto f = index().nearest_front(ray);
    if (!f) return std::nullopt;
    return locate(f->surface, f->hit.s, f->hit.t, f->hit.dist);
}

void SceneGeometry::intersect_front(const Ray* rays, std::size_t count, std::optional<Hit>* hits) const {
    if (surface_count() < kRayIndexMinSurfaces) {
        for (std::size_t i = 0; i < count; ++i) hits[i] = intersect_front_by_loop(rays[i]);
        return;
    }
    const RayIndex& rays_index = index();
    constexpr std::size_t kChunk = 64;  // on the stack: no allocation per call
    RayIndex::Found found[kChunk];
    for (std::size_t first = 0; first < count; first += kChunk) {
        const std::size_t n = std::min(kChunk, count - first);
        rays_index.nearest_front(rays + first, n, found);
        for (std::size_t i = 0; i < n; ++i) {
            const RayIndex::Found& f = found[i];
            if (f.surface < 0)
                hits[first + i].reset();
            else
                hits[first + i].emplace(locate(f.surface, f.hit.s, f.hit.t, f.hit.dist));
        }
    }
}

std::optional<Hit> SceneGeometry::intersect_front_by_loop(const Ray& ray) const {
    double best = std::numeric_limits<double>::infinity();
    std::optional<Hit> hit;
    for (int k = 0; k < surface_count(); ++k) {
        if (auto h = m_surfaces[k]->intersect(ray, 0.0, best, HitSide::FrontOnly)) {
            best = h->dist;
            hit = locate(k, h->s, h->t, h->dist);
        }
    }
    return hit;
}

std::string SceneGeometry::patch_label(int i) const {
    const Patch& p = m_patches[i];
    return m_names[p.surface] + "[" + std::to_string(p.is) + "," + std::to_string(p.it) + "]";
}

}  // namespace radiosa
