#pragma once
// The scene as read from a file: plain data, validated, knowing nothing of solving.
#include <array>
#include <string>
#include <vector>

#include "util/error.h"
#include "util/math.h"

namespace radiosa {

enum class SurfaceType { Quad, Sphere };

// Emission of one patch that replaces the surface's emission there.
struct PatchEmission {
    int is = 0;  // patch index along s, 0-based
    int it = 0;  // patch index along t, 0-based
    Rgb emission{0.0};
    FileLoc loc;
};

struct SurfaceDesc {
    std::string name;
    SurfaceType type = SurfaceType::Quad;
    FileLoc loc;

    // quad: P(s,t) is the bilinear map of four coplanar corners, P(0,0) = corners[0],
    // P(1,0) = corners[1], P(1,1) = corners[2], P(0,1) = corners[3]. The front (lit,
    // visible) side is the one the normal (c1 - c0) x (c3 - c0) points to.
    std::array<Vec3, 4> corners{};

    // sphere: azimuth 2 pi s around +z from +x, polar angle pi (1 - t) from +z
    // (t = 0 south pole, t = 1 north pole). Front side outward unless `inward`.
    Vec3 center{0.0};
    double radius = 0.0;
    bool inward = false;

    int ns = 1;  // patches along s
    int nt = 1;  // patches along t
    Rgb reflectance{0.0};
    Rgb emission{0.0};
    std::vector<PatchEmission> patch_emission;
};

struct FormFactorSettings {
    double tolerance = 0.0;  // absolute tolerance on each F_ij (error-controlled); 0 = not given
    int gauss_points = 0;    // the paper's fixed rule, p points per parameter; 0 = not given
    bool visibility = true;  // test occlusion
};

struct Scene {
    std::string name;
    std::string file;
    // A closed scene encloses all its energy: rows of F sum to 1, and emitted power equals
    // absorbed power. Open scenes are allowed; closure figures are then not reported.
    bool closed = true;
    FormFactorSettings form_factors;
    std::vector<SurfaceDesc> surfaces;

    int patch_count() const;
    int find_surface(const std::string& name) const;  // -1 when absent
};

// Limits that keep a typo from asking for an impossible run: the form-factor matrix is
// dense, N^2 doubles (20,000 patches = 3.2 GB), and the quadrature is O(N^2 p^4).
inline constexpr int kMaxPatchesPerAxis = 4096;
inline constexpr int kMaxPatches = 20000;
inline constexpr int kMaxGaussPoints = 64;
inline constexpr double kMinFormFactorTolerance = 1e-12;  // below this, round-off dominates

Scene load_scene(const std::string& path);
Scene parse_scene(const std::string& yaml_text, const std::string& filename);

}  // namespace radiosa
