#include "formfactor/shadow_occluder.h"

#include <algorithm>
#include <cmath>

#include "formfactor/cap_shadow.h"
#include "formfactor/disk_shadow.h"
#include "formfactor/point_polygon.h"
#include "formfactor/tube_shadow.h"
#include "util/convex_distance.h"

namespace radiosa {

std::optional<ShadowOccluder> shadow_occluder(const Surface& s) {
    if (const auto b = s.sphere(); b && s.whole_sphere()) return ShadowOccluder{*b};
    if (const auto d = s.flat_disk()) return ShadowOccluder{*d};
    if (const auto t = s.round_frustum()) return ShadowOccluder{*t};
    if (const auto c = s.spherical_cap()) return ShadowOccluder{*c};
    return std::nullopt;
}

double hidden_by(const ShadowOccluder& o, const Vec3& x, const Vec3& n, const std::array<Vec3, 4>& v,
                 double* error) {
    if (const auto* b = std::get_if<BoundingSphere>(&o))
        return point_to_polygon_blocked(x, n, v.data(), 4, *b);
    ShadowValue h;
    if (const auto* d = std::get_if<FlatDisk>(&o))
        h = point_to_polygon_hidden_by_disk(x, n, v.data(), 4, *d);
    else if (const auto* t = std::get_if<RoundFrustum>(&o))
        h = point_to_polygon_hidden_by_tube(x, n, v.data(), 4, *t);
    else
        h = point_to_polygon_hidden_by_cap(x, n, v.data(), 4, std::get<SphericalCap>(o));
    if (error) *error += h.error;
    return h.value;
}

bool has_corners(const ShadowOccluder& o) {
    return std::holds_alternative<RoundFrustum>(o) || std::holds_alternative<SphericalCap>(o);
}

bool hull_meets(std::span<const Vec3> hull, const ShadowOccluder& o) {
    if (const auto* b = std::get_if<BoundingSphere>(&o)) {
        const std::array<Vec3, 1> c = {b->center};
        return convex_distance(hull, c, b->radius) <= b->radius;
    }
    if (const auto* d = std::get_if<FlatDisk>(&o)) return hull_meets_disk(hull, *d);
    if (const auto* t = std::get_if<RoundFrustum>(&o)) return hull_meets_tube(hull, *t);
    return hull_meets_cap(hull, std::get<SphericalCap>(o));
}

double min_signed_distance(const ShadowOccluder& occ, const Vec3& m, double o) {
    if (const auto* b = std::get_if<BoundingSphere>(&occ)) return glm::dot(m, b->center) - o - b->radius;
    if (const auto* d = std::get_if<FlatDisk>(&occ)) return disk_min_signed_distance(*d, m, o);
    if (const auto* t = std::get_if<RoundFrustum>(&occ)) return tube_min_signed_distance(*t, m, o);
    return cap_min_signed_distance(std::get<SphericalCap>(occ), m, o);
}

bool shadows_apart(const BoundingSphere& patch, const BoundingSphere& a, const BoundingSphere& b) {
    const Vec3 da = a.center - patch.center, db = b.center - patch.center;
    const double la = glm::length(da), lb = glm::length(db);
    if (!(la - patch.radius > a.radius && lb - patch.radius > b.radius)) return false;
    const double apart = std::acos(std::clamp(glm::dot(da, db) / (la * lb), -1.0, 1.0));
    const double turn = std::asin(patch.radius / la) + std::asin(patch.radius / lb);
    const double wide = std::asin(a.radius / (la - patch.radius)) + std::asin(b.radius / (lb - patch.radius));
    return apart - turn - wide > 1e-9;
}

std::optional<std::vector<ShadowOccluder>> occluders_apart(const SceneGeometry& g,
                                                           const std::vector<int>& blockers,
                                                           const BoundingSphere& from, const Plane& a,
                                                           const Plane& b) {
    const double margin = 1e-9 * g.scale();
    std::vector<ShadowOccluder> out;
    std::vector<int> taken;
    for (int k : blockers) {
        if (std::find(taken.begin(), taken.end(), g.twin(k)) != taken.end()) continue;
        const auto o = shadow_occluder(g.surface(k));
        if (!o || !(min_signed_distance(*o, a.normal, a.offset) > margin) ||
            !(min_signed_distance(*o, b.normal, b.offset) > margin))
            return std::nullopt;
        for (int l : taken)
            if (!shadows_apart(from, g.surface_bound(l), g.surface_bound(k))) return std::nullopt;
        taken.push_back(k);
        out.push_back(*o);
    }
    return out;
}

}  // namespace radiosa
