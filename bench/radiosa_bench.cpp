// Stage benchmarks (Google Benchmark) on the 1991 paper's scene: form factors with and without
// culling, the solve (factorisation, a new lighting by substitution, the paper's Gauss-Jordan),
// one rendered frame, and loading the cached matrix. Results and the machine they ran on are
// kept in docs/generated/bench.md (tools/regen-docs bench); compare figures as ratios within one run (2-core
// machines are noisy).
//
//   build/radiosa_bench                       # everything
//   build/radiosa_bench --benchmark_filter=FormFactors
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "../tests/test_scenes.h"
#include "cache/cache_file.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/raycast.h"
#include "render/shading.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "solve/solver.h"

namespace radiosa {
namespace {

struct Seed {
    Scene scene = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    SceneGeometry geometry{scene};
    FormFactors ff = compute_form_factors(geometry, FormFactorOptions::adaptive(kDefaultFormFactorTolerance));
    Materials materials = patch_materials(scene);
};

const Seed& seed() {
    static const Seed s;
    return s;
}

void count_pairs(benchmark::State& state, const FormFactorStats& st) {
    state.counters["pairs_culled"] = static_cast<double>(st.pairs_culled);
    state.counters["segment_tests"] = static_cast<double>(st.segment_tests);
}

// args: {0 = the paper's Gauss rule p = 6, 1 = error control at 1e-6} x {culling off, on}
void FormFactors_Seed(benchmark::State& state) {
    const bool adaptive = state.range(0) == 1;
    FormFactorOptions o =
        adaptive ? FormFactorOptions::adaptive(kDefaultFormFactorTolerance) : FormFactorOptions::gauss(6);
    o.culling = state.range(1) == 1;
    const Seed& s = seed();  // built outside the timed loop
    FormFactorStats st;
    for (auto _ : state) {
        const FormFactors ff = compute_form_factors(s.geometry, o);
        st = ff.stats;
        benchmark::DoNotOptimize(ff.F.data.data());
    }
    count_pairs(state, st);
    state.SetLabel(std::string(adaptive ? "adaptive 1e-6" : "gauss p=6") +
                   (o.culling ? ", culling" : ", no culling"));
}
// Error control without culling takes ~25 s per run (docs/benchmarks.md): one iteration.
BENCHMARK(FormFactors_Seed)->Args({0, 1})->Args({0, 0})->Args({1, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(FormFactors_Seed)->Args({1, 0})->Iterations(1)->Unit(benchmark::kMillisecond);

// args: solver method (as SolverMethod)
void Factorise_Seed(benchmark::State& state) {
    const auto method = static_cast<SolverMethod>(state.range(0));
    const Seed& s = seed();
    for (auto _ : state) {
        const RadiositySolver solver(s.ff.F, s.materials.rho, method);
        benchmark::DoNotOptimize(solver.factorisations());
    }
    state.SetLabel(solver_method_name(method));
}
BENCHMARK(Factorise_Seed)->Arg(static_cast<int>(SolverMethod::LU))->Unit(benchmark::kMicrosecond);

// A new lighting: LU substitution into the kept factorisation, against the solvers that redo
// everything (the paper's Gauss-Jordan, the iterative methods).
void Solve_Seed(benchmark::State& state) {
    const auto method = static_cast<SolverMethod>(state.range(0));
    const Seed& s = seed();
    const RadiositySolver solver(s.ff.F, s.materials.rho, method);
    for (auto _ : state) benchmark::DoNotOptimize(solver.solve(s.materials.E).data());
    state.SetLabel(solver_method_name(method));
}
BENCHMARK(Solve_Seed)
    ->Arg(static_cast<int>(SolverMethod::LU))
    ->Arg(static_cast<int>(SolverMethod::GaussJordan))
    ->Arg(static_cast<int>(SolverMethod::Jacobi))
    ->Arg(static_cast<int>(SolverMethod::GaussSeidel))
    ->Arg(static_cast<int>(SolverMethod::Southwell))
    ->Unit(benchmark::kMicrosecond);

// One 512 x 512 frame of image A, 3 x 3 rays per pixel, exact ray casting.
void Render_Seed(benchmark::State& state) {
    const Seed& s = seed();
    const RadiositySolver solver(s.ff.F, s.materials.rho, SolverMethod::LU);
    const NodeRadiosity nodes(s.geometry, solver.solve(s.materials.E), s.materials.E);
    RenderOptions ro;
    ro.width = ro.height = static_cast<int>(state.range(0));
    const PinholeCamera cam(load_camera(RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml"), ro.width,
                            ro.height);
    for (auto _ : state) benchmark::DoNotOptimize(render_image(s.geometry, nodes, cam, ro).rgb.data());
    state.counters["rays/s"] =
        benchmark::Counter(static_cast<double>(ro.width) * ro.height * ro.samples * ro.samples,
                           benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(Render_Seed)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

// A closed box of side 10 holding n balls of radius 0.15 on a grid (a stand-in for scenes/
// spheres-1k.yaml's geometry), and 65,536 rays from a pinhole camera in one corner.
struct Balls {
    explicit Balls(int n) : scene(make(n)), geometry(scene) {
        const int side = 256;
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                const Vec3 d(1.0, -0.6 + 1.2 * x / side, -0.6 + 1.2 * y / side);
                rays.push_back(Ray{Vec3(-4.9, 0.0, 0.0), d});
            }
    }
    static Scene make(int n) {
        std::string s = "closed: true\nsurfaces:\n";
        s += test::cube_faces(5);
        const int g = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
        for (int b = 0; b < n; ++b) {
            const double x = -4 + 8.0 * (b % g) / g, y = -4 + 8.0 * ((b / g) % g) / g,
                         z = -4 + 8.0 * (b / (g * g)) / g;
            s += "  - {name: b" + std::to_string(b) + ", type: sphere, center: [" + std::to_string(x) + ", " +
                 std::to_string(y) + ", " + std::to_string(z) +
                 "], radius: 0.15, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}\n";
        }
        return parse_scene(s, "balls.yaml");
    }
    Scene scene;
    SceneGeometry geometry;
    std::vector<Ray> rays;
};

// args: {balls} x {0 = a loop over every surface, 1 = the BVH (geometry/ray_index.h) one ray at a
// time, 2 = the BVH in packets of eight neighbouring rays, as images trace them}
void Rays_Balls(benchmark::State& state) {
    const Balls b(static_cast<int>(state.range(0)));
    const int mode = static_cast<int>(state.range(1));
    benchmark::DoNotOptimize(b.geometry.intersect_front(b.rays[0]));  // builds the index, untimed
    std::vector<std::optional<Hit>> found(b.rays.size());
    for (auto _ : state) {
        int hits = 0;
        if (mode == 2) {
            b.geometry.intersect_front(b.rays.data(), b.rays.size(), found.data());
            for (const auto& h : found) hits += h.has_value();
        } else {
            for (const Ray& r : b.rays)
                hits += (mode == 1 ? b.geometry.intersect_front(r) : b.geometry.intersect_front_by_loop(r))
                            .has_value();
        }
        benchmark::DoNotOptimize(hits);
    }
    state.counters["rays/s"] =
        benchmark::Counter(static_cast<double>(b.rays.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(Rays_Balls)
    ->Args({10, 0})
    ->Args({10, 1})
    ->Args({10, 2})
    ->Args({100, 0})
    ->Args({100, 1})
    ->Args({100, 2})
    ->Args({1000, 0})
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Unit(benchmark::kMillisecond);

// One 1920 x 1080 frame of scenes/spheres-1k.yaml (1,006 surfaces, 31,536 patches) at one ray per
// pixel from cameras/spheres-1k.yaml, once solved: the target is 100 ms on 2 cores. The
// cost of a frame does not depend on the radiosities, so each patch takes E + rho / 2 instead of
// a solve (whose form factors take far longer than the frame).
void Render_Spheres1k(benchmark::State& state) {
    static const Scene scene = load_scene(RADIOSA_SOURCE_DIR "/scenes/spheres-1k.yaml");
    static const SceneGeometry geometry(scene);
    const Materials m = patch_materials(scene);
    std::vector<Rgb> B(m.E.size());
    for (std::size_t i = 0; i < B.size(); ++i) B[i] = m.E[i] + 0.5 * m.rho[i];
    const NodeRadiosity nodes(geometry, B, m.E);
    RenderOptions ro;
    ro.width = 1920;
    ro.height = 1080;
    ro.samples = 1;
    const PinholeCamera cam(load_camera(RADIOSA_SOURCE_DIR "/cameras/spheres-1k.yaml"), ro.width, ro.height);
    benchmark::DoNotOptimize(render_image(geometry, nodes, cam, ro).rgb.data());  // builds the index, untimed
    for (auto _ : state) benchmark::DoNotOptimize(render_image(geometry, nodes, cam, ro).rgb.data());
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(ro.width) * ro.height,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(Render_Spheres1k)->Unit(benchmark::kMillisecond)->UseRealTime();

// Loading the cached matrix (with every check: sizes, checksum, key, patch table, sense checks).
void CacheLoad_Seed(benchmark::State& state) {
    const Seed& s = seed();
    const auto path = std::filesystem::temp_directory_path() / "radiosa_bench_seed.rff";
    const FormFactorOptions o = FormFactorOptions::adaptive(kDefaultFormFactorTolerance);
    const CacheKey key = form_factor_key(s.scene, o);
    write_cache_file(path, key, s.scene.name, s.scene.closed, s.geometry, s.ff);
    const CacheExpectation expect{key, &s.geometry, o, s.scene.closed};
    for (auto _ : state) benchmark::DoNotOptimize(read_cache_file(path, expect).F.data.data());
    state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
    std::filesystem::remove(path);
}
BENCHMARK(CacheLoad_Seed)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace radiosa

BENCHMARK_MAIN();
