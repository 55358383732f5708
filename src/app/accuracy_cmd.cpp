#include "app/accuracy_cmd.h"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>

#include "formfactor/analytic.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "surfaces/quad.h"
#include "surfaces/registry.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

struct ErrorStats {
    double max = 0.0, mean = 0.0;
    int count = 0;
    void add(double e) {
        e = std::abs(e);
        max = std::max(max, e);
        mean += (e - mean) / ++count;
    }
};

// A configuration: a scene and how to measure the error of its matrix.
struct Config {
    std::string name;
    std::function<Scene()> scene;
    std::function<ErrorStats(const FormFactors&, const SceneGeometry&)> error;
    // The same configuration with its curved surface replaced by N flat facets (0: none).
    std::function<Scene(int)> faceted;
};

struct Row {
    std::string config, method;
    double parameter = 0, seconds = 0;
    ErrorStats err;
};

std::string quad_yaml(const std::string& name, const std::string& corners, int n = 1) {
    return "  - name: " + name + "\n    type: quad\n    corners: " + corners + "\n    patches: [" +
           std::to_string(n) + ", " + std::to_string(n) + "]\n    reflectance: [0, 0, 0]\n";
}
Scene yaml_scene(const std::string& surfaces, bool closed = false) {
    return parse_scene(std::string("closed: ") + (closed ? "true" : "false") + "\nsurfaces:\n" + surfaces,
                       "accuracy");
}

// Quads of a cube of side 2h centred at the origin, normals inwards, n x n patches each.
std::string cube_faces(int n = 1, double h = 2.0) {
    auto q = [h](std::initializer_list<std::array<int, 3>> corners) {
        std::array<std::string, 4> v;
        std::size_t k = 0;
        for (const auto& c : corners)
            v[k++] = fmt::format("[{:g}, {:g}, {:g}]", c[0] * h, c[1] * h, c[2] * h);
        return fmt::format("[{}, {}, {}, {}]", v[0], v[1], v[2], v[3]);
    };
    return quad_yaml("floor", q({{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}}), n) +
           quad_yaml("ceiling", q({{-1, -1, 1}, {-1, 1, 1}, {1, 1, 1}, {1, -1, 1}}), n) +
           quad_yaml("x0", q({{-1, -1, -1}, {-1, 1, -1}, {-1, 1, 1}, {-1, -1, 1}}), n) +
           quad_yaml("x1", q({{1, -1, -1}, {1, -1, 1}, {1, 1, 1}, {1, 1, -1}}), n) +
           quad_yaml("y0", q({{-1, -1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, -1, -1}}), n) +
           quad_yaml("y1", q({{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}}), n);
}

// Closure of a closed scene: every row sum's distance from 1.
ErrorStats closure_errors(const FormFactors& ff, const SceneGeometry&) {
    ErrorStats e;
    for (int i = 0; i < ff.F.n; ++i) {
        double row = 0.0;
        for (int j = 0; j < ff.F.n; ++j) row += ff.F(i, j);
        e.add(row - 1.0);
    }
    return e;
}

// The unit sphere as n_az x n_pol flat facets with vertices on it (triangles at the poles).
void add_facets(Scene* scene, int n_az, int n_pol) {
    auto p = [](double az, double pol) {
        return Vec3(std::sin(pol) * std::cos(az), std::sin(pol) * std::sin(az), std::cos(pol));
    };
    for (int b = 0; b < n_pol; ++b)
        for (int a = 0; a < n_az; ++a) {
            const double a0 = 2 * kPi * a / n_az, a1 = 2 * kPi * (a + 1) / n_az;
            const double t0 = kPi * b / n_pol, t1 = kPi * (b + 1) / n_pol;
            std::vector<Vec3> v = {p(a0, t1), p(a1, t1), p(a1, t0), p(a0, t0)};
            std::vector<Vec3> u;
            for (const Vec3& x : v)
                if (u.empty() || glm::length(x - u.back()) > 1e-12) u.push_back(x);
            if (u.size() > 1 && glm::length(u.front() - u.back()) < 1e-12) u.pop_back();
            Vec3 c(0.0), nrm(0.0);
            for (std::size_t k = 0; k < u.size(); ++k) {
                c += u[k];
                nrm += glm::cross(u[k], u[(k + 1) % u.size()]);
            }
            if (glm::dot(nrm, c) < 0.0) std::reverse(u.begin(), u.end());
            SurfaceDesc d;
            d.name = "facet" + std::to_string(scene->surfaces.size());
            d.type = find_surface_type("quad");
            d.shape = std::make_shared<QuadSurface>(u[0], u[1], u[2], u.size() == 4 ? u[3] : u[2]);
            scene->surfaces.push_back(d);
        }
}

const std::string kSphere =
    "  - name: ball\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n    patches: [8, 4]\n"
    "    reflectance: [0, 0, 0]\n";

// Flat patches against closed forms (Howell's catalog).
std::vector<Config> planar_configurations() {
    using namespace analytic;
    std::vector<Config> c;
    auto pair01 = [](double exact) {
        return [exact](const FormFactors& ff, const SceneGeometry&) {
            ErrorStats e;
            e.add(ff.F(0, 1) - exact);
            e.add(ff.area[1] * ff.F(1, 0) / ff.area[0] - exact);
            return e;
        };
    };
    c.push_back({"opposed unit squares, distance 1",
                 [] {
                     return yaml_scene(quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]") +
                                       quad_yaml("b", "[[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]"));
                 },
                 pair01(parallel_rectangles(1, 1, 1)), nullptr});
    c.push_back({"perpendicular squares, shared edge",
                 [] {
                     return yaml_scene(quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]") +
                                       quad_yaml("b", "[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]"));
                 },
                 pair01(perpendicular_rectangles(1, 1, 1)), nullptr});
    c.push_back({"perpendicular squares, shared corner",
                 [] {
                     return yaml_scene(quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]") +
                                       quad_yaml("b", "[[1, 0, 0], [1, 0, 1], [2, 0, 1], [2, 0, 0]]"));
                 },
                 pair01(perpendicular_squares_corner()), nullptr});
    c.push_back({"perpendicular squares, gap 1e-3",
                 [] {
                     return yaml_scene(
                         quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]") +
                         quad_yaml("b", "[[0, 0, 0.001], [0, 0, 1.001], [1, 0, 1.001], [1, 0, 0.001]]"));
                 },
                 pair01(perpendicular_rectangles_gap(1, 1, 1e-3, 1)), nullptr});
    // Directly opposed unit squares a hair apart, at three scales: the contour closed form.
    for (double gap : {1e-3, 1e-6, 1e-9})
        for (double scale : {1e-6, 1.0, 1e6}) {
            const std::string k = fmt::format("{:.17g}", scale), z = fmt::format("{:.17g}", gap * scale);
            const std::string lower = fmt::format("[[0, 0, 0], [{0}, 0, 0], [{0}, {0}, 0], [0, {0}, 0]]", k);
            const std::string upper =
                fmt::format("[[0, 0, {1}], [0, {0}, {1}], [{0}, {0}, {1}], [{0}, 0, {1}]]", k, z);
            c.push_back({fmt::format("opposed unit squares, gap {:g}, scale {:g}", gap, scale),
                         [=] { return yaml_scene(quad_yaml("a", lower) + quad_yaml("b", upper)); },
                         pair01(parallel_rectangles(1, 1, gap)), nullptr});
        }
    c.push_back({"opposed 1 x 1e-4 strips, distance 1",
                 [] {
                     return yaml_scene(quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1e-4, 0], [0, 1e-4, 0]]") +
                                       quad_yaml("b", "[[0, 0, 1], [0, 1e-4, 1], [1, 1e-4, 1], [1, 0, 1]]"));
                 },
                 pair01(parallel_rectangles(1, 1e-4, 1)), nullptr});
    return c;
}

// Curved surfaces: the sphere's inside, nested spheres, a sphere in a cube, the seed scene.
std::vector<Config> curved_configurations() {
    using namespace analytic;
    std::vector<Config> c;
    c.push_back({"inside of a sphere, 8 x 4 patches",
                 [] {
                     return yaml_scene(
                         "  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n"
                         "    facing: inward\n    patches: [8, 4]\n    reflectance: [0, 0, 0]\n",
                         true);
                 },
                 [](const FormFactors& ff, const SceneGeometry&) {
                     ErrorStats e;
                     for (int i = 0; i < ff.F.n; ++i)
                         for (int j = 0; j < ff.F.n; ++j) e.add(ff.F(i, j) - ff.area[j] / (4 * kPi));
                     return e;
                 },
                 nullptr});
    c.push_back({"concentric spheres, radii 1 and 2",
                 [] {
                     return yaml_scene(
                         kSphere +
                             "  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n    radius: 2\n"
                             "    facing: inward\n    patches: [8, 4]\n    reflectance: [0, 0, 0]\n",
                         true);
                 },
                 [](const FormFactors& ff, const SceneGeometry&) {
                     // Inner patches send everything to the shell; every shell patch sends
                     // (r/R)^2 = 1/4 to the inner sphere.
                     ErrorStats e;
                     for (int i = 0; i < 64; ++i) {
                         double to_inner = 0.0;
                         for (int j = 0; j < 32; ++j) to_inner += ff.F(i, j);
                         e.add(to_inner - (i < 32 ? 0.0 : 0.25));
                     }
                     return e;
                 },
                 nullptr});
    const double face_to_ball = kPi / 24.0;  // (4 pi R^2 / 6) / 16 with R = 1, side 4
    c.push_back({"cube face to sphere (side 4, radius 1)",
                 [] { return yaml_scene(cube_faces() + kSphere, true); },
                 [face_to_ball](const FormFactors& ff, const SceneGeometry& g) {
                     ErrorStats e;
                     for (int f = 0; f < 6; ++f) {
                         double s = 0.0;
                         for (int j = 6; j < g.patch_count(); ++j) s += ff.F(f, j);
                         e.add(s - face_to_ball);
                     }
                     return e;
                 },
                 [](int facets) {
                     Scene s = yaml_scene(cube_faces(), true);
                     const int n_pol = static_cast<int>(std::lround(std::sqrt(facets / 2.0)));
                     add_facets(&s, 2 * n_pol, n_pol);
                     return s;
                 }});
    c.push_back({"concentric spheres, one patch each",
                 [] {
                     return yaml_scene(
                         "  - name: ball\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n"
                         "    patches: [1, 1]\n    reflectance: [0, 0, 0]\n"
                         "  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n    radius: 2\n"
                         "    facing: inward\n    patches: [1, 1]\n    reflectance: [0, 0, 0]\n",
                         true);
                 },
                 [](const FormFactors& ff, const SceneGeometry&) {
                     ErrorStats e;  // 1, 0 | 1/4, 3/4
                     e.add(ff.F(0, 1) - 1.0);
                     e.add(ff.F(1, 0) - 0.25);
                     e.add(ff.F(1, 1) - 0.75);
                     return e;
                 },
                 nullptr});
    return c;
}

// Closed scenes whose rows must sum to 1.
std::vector<Config> closure_configurations() {
    std::vector<Config> c;
    c.push_back({"sphere of radius 0.9 in the cube [-1, 1]^3, faces 3 x 3: closure",
                 [] {
                     return yaml_scene(
                         cube_faces(3, 1.0) +
                             "  - name: ball\n    type: sphere\n    center: [0, 0, 0]\n"
                             "    radius: 0.9\n    patches: [8, 4]\n    reflectance: [0, 0, 0]\n",
                         true);
                 },
                 closure_errors, nullptr});
    c.push_back({"seed scene closure (86 patches)",
                 [] { return yaml_scene(cube_faces(3) + kSphere, true); },  // the seed scene's geometry
                 closure_errors, nullptr});
    return c;
}

std::vector<Config> configurations() {
    std::vector<Config> c = planar_configurations();
    for (Config& k : curved_configurations()) c.push_back(std::move(k));
    for (Config& k : closure_configurations()) c.push_back(std::move(k));
    return c;
}

}  // namespace

void run_accuracy(const AccuracyJob& job, std::ostream& out) {
    std::error_code ec;
    fs::create_directories(job.out_dir, ec);
    if (ec) throw Error(job.out_dir + ": cannot create the output directory: " + ec.message());
    std::unique_ptr<tbb::global_control> limit;
    if (job.threads > 0)
        limit =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, job.threads);

    const std::vector<Config> configs = configurations();
    {  // warm up (thread pool, Gauss tables) so the first timing is not an outlier
        const Scene s = configs.front().scene();
        compute_form_factors(SceneGeometry(s), FormFactorOptions::adaptive(1e-6));
    }
    std::vector<Row> rows;
    auto run = [&](const Config& c, const Scene& scene, const std::string& method, double param,
                   const FormFactorOptions& o) {
        const SceneGeometry g(scene);
        const Stopwatch clock;
        const FormFactors ff = compute_form_factors(g, o);
        Row r{c.name, method, param, clock.seconds(), c.error(ff, g)};
        out << fmt::format("  {:<40} {:<9} {:<8} {:9.4f} s  max error {:.2e}  mean {:.2e}\n", c.name, method,
                           fmt::format("{:g}", param), r.seconds, r.err.max, r.err.mean)
            << std::flush;
        rows.push_back(r);
        return r.seconds;
    };
    const std::vector<int> ps =
        job.quick ? std::vector<int>{2} : std::vector<int>{1, 2, 3, 4, 5, 6, 8, 10, 12, 14, 16};
    const std::vector<double> tols =
        job.quick ? std::vector<double>{1e-3}
                  : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
    const std::vector<int> facets = job.quick ? std::vector<int>{32} : std::vector<int>{32, 128, 512, 2048};
    for (const Config& c : configs) {
        const Scene scene = c.scene();
        for (int p : ps)
            if (run(c, scene, "gauss", p, FormFactorOptions::gauss(p)) > job.budget_s) break;
        for (double t : tols)
            if (run(c, scene, "adaptive", t, FormFactorOptions::adaptive(t)) > job.budget_s) break;
        if (c.faceted)
            for (int n : facets)
                // The faceted sphere is convex, so nothing can block a face-to-facet pair: with
                // visibility off the closed-form inner integral applies to every such pair and the
                // error measured is the faceting's alone.
                if (run(c, c.faceted(n), "faceted", n, FormFactorOptions::adaptive(1e-9, false)) >
                    job.budget_s)
                    break;
    }

    const fs::path dir(job.out_dir);
    std::ostringstream csv, md;
    csv << "config,method,parameter,seconds,max_error,mean_error\n";
    md << "| configuration | method | parameter | seconds | max error | mean error "
          "|\n|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
        csv << fmt::format("\"{}\",{},{:g},{:.6g},{:.6e},{:.6e}\n", r.config, r.method, r.parameter,
                           r.seconds, r.err.max, r.err.mean);
        md << fmt::format("| {} | {} | {:g} | {:.4f} | {:.2e} | {:.2e} |\n", r.config, r.method, r.parameter,
                          r.seconds, r.err.max, r.err.mean);
    }
    write_text_file(dir / "accuracy.csv", csv.str());
    write_text_file(dir / "accuracy.md", md.str());
    out << "wrote " << (dir / "accuracy.csv").string() << " and " << (dir / "accuracy.md").string()
        << " (plot them with tools/plot-accuracy)\n";
}

}  // namespace radiosa
