#pragma once
// The surfaces that may block segments between two patches, each with its bounding sphere. A
// segment that keeps clear of a blocker's bounding sphere by a margin far above rounding cannot
// meet the blocker; a segment that dips deep into a whole sphere while both its ends stay well
// outside certainly crosses it. Both are answered without asking the surface, so only segments
// that graze a blocker pay for its exact test (a virtual call, a transform for a placed surface,
// square roots). The guard answers only where the exact test's answer is certain, so matrices
// are bit for bit what testing every blocker gives.
#include <cmath>
#include <vector>

#include "geometry/scene_geometry.h"

namespace radiosa {

class BlockerSet {
public:
    BlockerSet(const SceneGeometry& g, const std::vector<int>& blockers) {
        m_items.reserve(blockers.size());
        // Distances are computed to within a few ulps of the scene's size; 1e-9 of it is a
        // margin no rounding reaches.
        const double margin = 1e-9 * g.scale();
        for (const int k : blockers) {
            const Surface& s = g.surface(k);
            const BoundingSphere& b = g.surface_bound(k);
            const double r = b.radius + margin;
            Item it{&s, b.center, r * r, -1.0, 0.0, -1.0};
            // A whole sphere: segments are certain to cross it when they pass inside it by
            // kDeep of its radius (and that is far above rounding) with both ends outside.
            if (const auto sph = s.sphere(); sph && s.whole_sphere() && kDeep * sph->radius > margin) {
                it.center = sph->center;
                it.reach2 = (sph->radius + margin) * (sph->radius + margin);
                it.inner2 = (sph->radius * (1.0 - kDeep)) * (sph->radius * (1.0 - kDeep));
                it.depth = kDeep * sph->radius;
                it.outer2 = (sph->radius * (1.0 + kDeep)) * (sph->radius * (1.0 + kDeep));
            }
            m_items.push_back(it);
        }
    }
    bool empty() const { return m_items.empty(); }

    // The blockers that may meet some segment from x to a point within `radius` of `center`,
    // as indices in list order: a segment from x to such a point lies within `radius` of the
    // segment from x to the centre. A crowd of balls puts hundreds on a pair's list, and a
    // point's segments pass near few of them.
    void near_list(const Vec3& x, const Vec3& center, double radius, std::vector<int>* out) const {
        out->clear();
        const Vec3 e = center - x;
        const double l2 = glm::dot(e, e);
        for (std::size_t k = 0; k < m_items.size(); ++k) {
            const double reach = std::sqrt(m_items[k].reach2) + radius;
            if (distance2(x - m_items[k].center, e, l2) <= reach * reach) out->push_back(static_cast<int>(k));
        }
    }

    // True when a blocker meets the segment x + t e, t_min < t < t_max (0 <= t_min, t_max <= 1).
    // *tests counts the blockers in the pair's list up to the one that blocks (all when none
    // does), whether the guard or the surface answered.
    bool blocked(const Vec3& x, const Vec3& e, double t_min, double t_max, long long* tests) const {
        const double l2 = glm::dot(e, e);
        for (std::size_t k = 0; k < m_items.size(); ++k) {
            ++*tests;
            if (meets(m_items[k], x, e, l2, t_min, t_max)) return true;
        }
        return false;
    }

    // blocked() asked of the blockers in `near` only (from near_list(x, ...) for a segment's
    // far end in that ball): the same answer, and *tests counts as blocked() counts.
    bool blocked_among(const Vec3& x, const Vec3& e, double t_min, double t_max, long long* tests,
                       const std::vector<int>& near) const {
        const double l2 = glm::dot(e, e);
        for (const int k : near)
            if (meets(m_items[static_cast<std::size_t>(k)], x, e, l2, t_min, t_max)) {
                *tests += k + 1;
                return true;
            }
        *tests += static_cast<long long>(m_items.size());
        return false;
    }

private:
    static constexpr double kDeep = 1e-6;

    struct Item {
        const Surface* surface;
        Vec3 center;
        double reach2;  // (bounding radius + margin)^2
        double inner2;  // whole spheres: (R (1 - kDeep))^2, else negative
        double depth;   // kDeep R
        double outer2;  // (R (1 + kDeep))^2
    };

    // The squared distance from a point to the segment oc + t e, 0 <= t <= 1 (l2 = |e|^2),
    // with the point at the origin.
    static double distance2(const Vec3& oc, const Vec3& e, double l2) {
        const double b = glm::dot(oc, e);
        Vec3 closest = oc;  // t = 0
        if (b < 0.0) closest = -b >= l2 ? oc + e : oc - (b / l2) * e;
        return glm::dot(closest, closest);
    }

    // True when the blocker meets the segment x + t e (l2 = |e|^2), t_min < t < t_max: the
    // guard answers where it is certain, the surface's exact test otherwise.
    static bool meets(const Item& it, const Vec3& x, const Vec3& e, double l2, double t_min, double t_max) {
        const Vec3 oc = x - it.center;
        const double d2 = distance2(oc, e, l2);
        if (d2 > it.reach2) return false;
        return crosses(it, oc, e, d2, l2, t_min, t_max) || it.surface->blocks(Ray{x, e}, t_min, t_max);
    }

    // True when the segment certainly crosses a whole sphere between t_min and t_max: its
    // closest point lies inside by kDeep R and both ends lie outside by kDeep R, so the line
    // enters and leaves the ball at parameters at least depth / |e| from either end.
    static bool crosses(const Item& it, const Vec3& oc, const Vec3& e, double d2, double l2, double t_min,
                        double t_max) {
        if (!(d2 < it.inner2) || glm::dot(oc, oc) <= it.outer2) return false;
        const Vec3 end = oc + e;
        if (glm::dot(end, end) <= it.outer2) return false;
        const double gap = 0.5 * it.depth;  // half of the certain distance, in length
        return gap * gap > l2 * t_min * t_min && gap * gap > l2 * (1.0 - t_max) * (1.0 - t_max);
    }

    std::vector<Item> m_items;
};

}  // namespace radiosa
