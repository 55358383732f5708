#include "surfaces/registry.h"

namespace radiosa {

// Defined in each type's own file.
extern const SurfaceType kQuadType;
extern const SurfaceType kSphereType;
extern const SurfaceType kDiskType;
extern const SurfaceType kCylinderType;
extern const SurfaceType kConeType;
extern const SurfaceType kTorusType;
extern const SurfaceType kBezierType;
extern const SurfaceType kTriangleType;
extern const SurfaceType kMeshType;

const std::vector<const SurfaceType*>& surface_types() {
    static const std::vector<const SurfaceType*> types = {&kQuadType,     &kSphereType,   &kDiskType,
                                                          &kCylinderType, &kConeType,     &kTorusType,
                                                          &kBezierType,   &kTriangleType, &kMeshType};
    return types;
}

const SurfaceType* find_surface_type(std::string_view name) {
    for (const SurfaceType* t : surface_types())
        if (t->name == name) return t;
    return nullptr;
}

std::string surface_type_names() {
    std::string s;
    for (const SurfaceType* t : surface_types()) s += (s.empty() ? "" : ", ") + t->name;
    return s;
}

}  // namespace radiosa
