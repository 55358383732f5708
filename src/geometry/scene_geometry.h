#pragma once
// The scene's surfaces as parametric maps, split into patches, with exact ray queries.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

class RayIndex;

struct Scene;

// A patch: the parameter rectangle [s0,s1] x [t0,t1] of one surface.
struct Patch {
    int surface = 0;
    int is = 0, it = 0;  // index along s and t on its surface
    double s0 = 0, s1 = 0, t0 = 0, t1 = 0;
    double area = 0;  // exact
    BoundingSphere bound;
    std::array<Vec3, 4> corners{};  // P(s0,t0), P(s1,t0), P(s1,t1), P(s0,t1)
    bool polygon = false;  // exactly the convex polygon of its corners (Surface::patches_are_polygons)
};

struct Hit {
    double dist = 0.0;
    int surface = -1;
    int patch = -1;       // global patch index
    double s = 0, t = 0;  // surface parameters
    double u = 0, v = 0;  // parameters local to the patch, in [0,1]
};

class SceneGeometry {
public:
    explicit SceneGeometry(const Scene& scene);

    int surface_count() const { return static_cast<int>(m_surfaces.size()); }
    const Surface& surface(int k) const { return *m_surfaces[k]; }
    const std::string& surface_name(int k) const { return m_names[k]; }
    int ns(int k) const { return m_ns[k]; }
    int nt(int k) const { return m_nt[k]; }
    int first_patch(int k) const { return m_first_patch[k]; }
    // The other side of a two-sided surface (the same geometry, facing the other way), or -1.
    int twin(int k) const { return m_twin[k]; }
    // The scene file's `surfaces` entry it came from (an entry may make several surfaces: a
    // type's parts, a back side), or -1 for a surface made otherwise.
    int entry(int k) const { return m_entry[k]; }
    int patch_index(int k, int is, int it) const { return m_first_patch[k] + it * m_ns[k] + is; }

    int patch_count() const { return static_cast<int>(m_patches.size()); }
    const Patch& patch(int i) const { return m_patches[i]; }
    const std::vector<Patch>& patches() const { return m_patches; }
    // A sphere containing the whole of surface k.
    const BoundingSphere& surface_bound(int k) const { return m_surface_bounds[k]; }
    // Characteristic size of the scene (diameter of its bounding sphere).
    double scale() const { return m_scale; }

    // The nearest front-facing surface point along the ray (one-sided surfaces: a ray
    // arriving from behind passes through). From kRayIndexMinSurfaces surfaces on, through a
    // BVH (geometry/ray_index.h, built on the first call); the same hits either way.
    std::optional<Hit> intersect_front(const Ray& ray) const;
    // hits[i] = intersect_front(rays[i]) for i < count; through the BVH in packets, faster for
    // coherent rays such as an image row's. There a whole sphere's hit parameters come from
    // SIMD angles: the same surface and distance, s and t within 1e-15.
    void intersect_front(const Ray* rays, std::size_t count, std::optional<Hit>* hits) const;
    // Below this many surfaces a loop over them is as fast as the BVH (docs/benchmarks.md).
    static constexpr int kRayIndexMinSurfaces = 8;
    // Every surface in turn: the reference the BVH is tested against.
    std::optional<Hit> intersect_front_by_loop(const Ray& ray) const;
    // A polygon patch's corners, counter-clockwise about its front normal.
    std::array<Vec3, 4> front_polygon(int patch) const;
    // Four corners of a flat piece of a surface, reordered if need be to run counter-clockwise
    // about `front` (its front normal), as front_polygon orders a patch's.
    static std::array<Vec3, 4> facing(std::array<Vec3, 4> v, const Vec3& front);
    // "surface[is,it]": how reports, exports and messages name a patch.
    std::string patch_label(int patch) const;
    // Maps surface parameters to the patch that owns them and the local (u, v).
    Hit locate(int surface, double s, double t, double dist) const;

private:
    std::vector<std::shared_ptr<const Surface>> m_surfaces;
    std::vector<std::string> m_names;
    std::vector<int> m_ns, m_nt, m_first_patch, m_twin, m_entry;
    std::vector<Patch> m_patches;
    std::vector<BoundingSphere> m_surface_bounds;
    double m_scale = 1.0;
    // Built once, on the first ray, shared by copies (the surfaces it points to are shared too).
    struct LazyIndex;
    std::shared_ptr<LazyIndex> m_index;
    const RayIndex& index() const;
};

}  // namespace radiosa
