#include "scene/scene.h"

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

}  // namespace radiosa
