#include "scene/scene.h"

#include <stdexcept>

namespace radiosa {

int Scene::patch_count() const {
    int n = 0;
    for (const auto& s : surfaces) n += s.ns * s.nt;
    return n;
}

int Scene::find_surface(const std::string& name) const {
    for (size_t i = 0; i < surfaces.size(); ++i)
        if (surfaces[i].name == name) return static_cast<int>(i);
    return -1;
}

Materials patch_materials(const Scene& scene) {
    Materials m;
    for (const SurfaceDesc& d : scene.surfaces) {
        const std::size_t first = m.rho.size();
        m.rho.resize(first + static_cast<std::size_t>(d.ns) * d.nt, d.reflectance);
        m.E.resize(m.rho.size(), d.emission);
        for (const auto& pe : d.patch_emission)
            m.E[first + static_cast<std::size_t>(pe.it) * d.ns + pe.is] = pe.emission;
    }
    return m;
}

std::shared_ptr<const Surface> moved_shape(const SurfaceDesc& d, const Similarity& motion) {
    if (motion.identity()) return d.shape;
    if (!d.unplaced) throw std::logic_error("moved_shape: surface '" + d.name + "' was not read from a file");
    return std::make_shared<PlacedSurface>(d.unplaced, compose(motion, d.transform), d.back);
}

}  // namespace radiosa
