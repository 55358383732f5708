// The `cylinder` surface type: an open tube, the frustum (cone.h) whose radii are equal.
#include "surfaces/cone.h"
#include "surfaces/registry.h"

namespace radiosa {

namespace {

// base, axis (base centre -> top centre), radius > 0, facing, angles_deg.
std::shared_ptr<const Surface> read_cylinder(YamlMap& m, const std::string&) {
    return read_frustum(m, false);
}

}  // namespace

extern const SurfaceType kCylinderType;
const SurfaceType kCylinderType = {
    .name = "cylinder",
    .key_id = 3,
    .keys = "base, axis, radius, facing, angles_deg",
    .read = read_cylinder,
    .example = {{"base", "[0, 0, 0]"},
                {"axis", "[0, 0, 1]"},
                {"radius", "1"},
                {"facing", "outward"},
                {"angles_deg", "[0, 360]"}},
    .variants = {{"base", "[0.5, 0, 0]"},
                 {"base", "[0, 0, 0.5]"},
                 {"axis", "[0, 0, 2]"},
                 {"axis", "[1, 0, 1]"},
                 {"radius", "1.5"},
                 {"facing", "inward"},
                 {"angles_deg", "[-90, 90]"}},
};

}  // namespace radiosa
