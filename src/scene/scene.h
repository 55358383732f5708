#pragma once
// The scene as read from a file: plain data, validated, knowing nothing of solving.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "surfaces/placed.h"
#include "util/error.h"
#include "util/math.h"

namespace radiosa {

// Emission of one patch that replaces the surface's emission there.
struct PatchEmission {
    int is = 0;  // patch index along s, 0-based
    int it = 0;  // patch index along t, 0-based
    Rgb emission{0.0};
    FileLoc loc;
};

struct SurfaceType;
class Surface;

struct SurfaceDesc {
    std::string name;
    const SurfaceType* type = nullptr;     // from the registry (surfaces/registry.h)
    std::shared_ptr<const Surface> shape;  // built and validated by the type's reader
    FileLoc loc;
    // How `shape` was made: `unplaced` placed by `transform` (the identity when the file gives
    // none), seen from the back when `back`. A motion in a sequence places it anew (moved_shape).
    std::shared_ptr<const Surface> unplaced;
    Similarity transform;
    bool back = false;

    int ns = 1;  // patches along s
    int nt = 1;  // patches along t
    Rgb reflectance{0.0};
    Rgb emission{0.0};
    std::vector<PatchEmission> patch_emission;
    // The index of the other side of a two-sided surface (two_sided: true), else -1.
    int twin = -1;
    // The index of the scene file's `surfaces` entry it came from: an entry can make several
    // surfaces (a type's parts, back sides).
    int entry = -1;
};

// A sensor: a differential element at `position` facing along `normal` (unit) that sees the
// scene with occlusion but takes no part in the solve and is not drawn (formfactor/sensor.h).
struct SensorDesc {
    std::string name;
    Vec3 position{0.0};
    Vec3 normal{0.0, 0.0, 1.0};
    FileLoc loc;
};

// The scene file's form_factors block; what it does not give, the command line or the
// defaults decide (formfactor/form_factor.h, resolve_form_factor_options).
struct FormFactorSettings {
    std::optional<double> tolerance;  // absolute tolerance on each F_ij (error-controlled)
    std::optional<int> gauss_points;  // the paper's fixed rule, p points per parameter
    bool visibility = true;           // test occlusion
    bool hierarchical = false;        // method: hierarchical (tolerance is then the links')
    // Hierarchical: the tolerance on each link's receiver misfit (FormFactorOptions); 0: off,
    // none: automatic.
    std::optional<double> receiver_tolerance;
    bool numeric_lines = false;  // numeric_inner: lines (FormFactorOptions)
};

// The scene file's solve block: a target on the radiosity itself.
struct SolveSettings {
    // max |B - B*| / max B per channel (B* with exact form factors): the form-factor tolerance is
    // tightened until the reported bound (radiosity_error_bound) meets it.
    std::optional<double> tolerance;
};

struct Scene {
    std::string name;
    std::string file;
    // A closed scene encloses all its energy: rows of F sum to 1, and emitted power equals
    // absorbed power. Open scenes are allowed; closure figures are then not reported.
    bool closed = true;
    FormFactorSettings form_factors;
    SolveSettings solve;
    FileLoc solve_loc;  // where the solve block is, for messages about it
    std::vector<SurfaceDesc> surfaces;
    std::vector<SensorDesc> sensors;  // `type: sensor` entries of the surfaces list, in order

    int patch_count() const;
    int find_surface(const std::string& name) const;  // -1 when absent
};

// Limits that keep a typo from asking for an impossible run. A scene holds at most
// kMaxPatches patches (the hierarchical method keeps no N x N array); the dense
// form-factor matrix, N^2 doubles and O(N^2 p^4) quadrature, stops at kMaxDensePatches
// (20,000 patches = 3.2 GB), checked where the method is known (app/pipeline.cpp).
inline constexpr int kMaxPatchesPerAxis = 4096;
inline constexpr int kMaxPatches = 1000000;
inline constexpr int kMaxDensePatches = 20000;
inline constexpr int kMaxGaussPoints = 64;
inline constexpr double kMinFormFactorTolerance = 1e-12;  // below this, round-off dominates
// A receiver tolerance, from the scene or the command line: 0 (off) or a tolerance.
inline bool valid_receiver_tolerance(double v) {
    return v == 0.0 || (v >= kMinFormFactorTolerance && v <= 0.1);
}

// Per-patch reflectance and emission, from the scene (patch_emission overrides included), in
// patch order (surface by surface, s fastest). Kept apart from the geometry: colours and lights
// change without new form factors.
struct Materials {
    std::vector<Rgb> rho;
    std::vector<Rgb> E;
};
Materials patch_materials(const Scene& scene);

// The surface displaced by a rigid `motion` applied after its own transform (a sequence's
// translate / rotate_deg events): `d.shape` itself for the identity, else the unplaced shape
// placed by compose(motion, transform), so that a surface without a transform moved by M is the
// same bits as one placed by `transform: M` in a scene file.
std::shared_ptr<const Surface> moved_shape(const SurfaceDesc& d, const Similarity& motion);

Scene load_scene(const std::string& path);
Scene parse_scene(const std::string& yaml_text, const std::string& filename);

}  // namespace radiosa
