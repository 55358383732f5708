#include "app/accuracy_cmd.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <tbb/global_control.h>

#include <algorithm>
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
    return "  - name: " + name + "\n    type: quad\n    corners: " + corners + "\n    patches: [" + std::to_string(n) +
           ", " + std::to_string(n) + "]\n    reflectance: [0, 0, 0]\n";
}
Scene yaml_scene(const std::string& surfaces, bool closed = false) {
    return parse_scene(std::string("closed: ") + (closed ? "true" : "false") + "\nsurfaces:\n" + surfaces, "accuracy");
}

// Quads of a cube of side 4 centred at the origin, normals inwards, one patch each.
std::string cube_faces(int n = 1) {
    return quad_yaml("floor", "[[-2, -2, -2], [2, -2, -2], [2, 2, -2], [-2, 2, -2]]", n) +
           quad_yaml("ceiling", "[[-2, -2, 2], [-2, 2, 2], [2, 2, 2], [2, -2, 2]]", n) +
           quad_yaml("x0", "[[-2, -2, -2], [-2, 2, -2], [-2, 2, 2], [-2, -2, 2]]", n) +
           quad_yaml("x1", "[[2, -2, -2], [2, -2, 2], [2, 2, 2], [2, 2, -2]]", n) +
           quad_yaml("y0", "[[-2, -2, -2], [-2, -2, 2], [2, -2, 2], [2, -2, -2]]", n) +
           quad_yaml("y1", "[[-2, 2, -2], [2, 2, -2], [2, 2, 2], [-2, 2, 2]]", n);
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
            d.type = SurfaceType::Quad;
            d.corners = {u[0], u[1], u[2], u.size() == 4 ? u[3] : u[2]};
            scene->surfaces.push_back(d);
        }
}

const std::string kSphere = "  - name: ball\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n    patches: [8, 4]\n"
                            "    reflectance: [0, 0, 0]\n";

std::vector<Config> configurations() {
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
                     return yaml_scene(quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]") +
                                       quad_yaml("b", "[[0, 0, 0.001], [0, 0, 1.001], [1, 0, 1.001], [1, 0, 0.001]]"));
                 },
                 pair01(perpendicular_rectangles_gap(1, 1, 1e-3, 1)), nullptr});
    c.push_back({"opposed 1 x 1e-4 strips, distance 1",
                 [] {
                     return yaml_scene(quad_yaml("a", "[[0, 0, 0], [1, 0, 0], [1, 1e-4, 0], [0, 1e-4, 0]]") +
                                       quad_yaml("b", "[[0, 0, 1], [0, 1e-4, 1], [1, 1e-4, 1], [1, 0, 1]]"));
                 },
                 pair01(parallel_rectangles(1, 1e-4, 1)), nullptr});
    c.push_back({"inside of a sphere, 8 x 4 patches",
                 [] {
                     return yaml_scene("  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n"
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
                     return yaml_scene(kSphere + "  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n    radius: 2\n"
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
    c.push_back({"seed scene closure (86 patches)",
                 [] { return yaml_scene(cube_faces(3) + kSphere, true); },  // the seed scene's geometry
                 [](const FormFactors& ff, const SceneGeometry&) {
                     ErrorStats e;
                     for (int i = 0; i < ff.F.n; ++i) {
                         double row = 0.0;
                         for (int j = 0; j < ff.F.n; ++j) row += ff.F(i, j);
                         e.add(row - 1.0);
                     }
                     return e;
                 },
                 nullptr});
    return c;
}

// ---- the plot ----

struct Canvas {
    int w, h;
    std::vector<float> rgb;
    Canvas(int width, int height) : w(width), h(height), rgb(static_cast<std::size_t>(width) * height * 3, 1.0f) {}
    void dot(int x, int y, const Vec3& c) {
        if (x < 0 || y < 0 || x >= w || y >= h) return;
        float* p = &rgb[3 * (static_cast<std::size_t>(y) * w + x)];
        p[0] = static_cast<float>(c.r);
        p[1] = static_cast<float>(c.g);
        p[2] = static_cast<float>(c.b);
    }
    void line(double x0, double y0, double x1, double y1, const Vec3& c, int thick = 1) {
        const int n = static_cast<int>(std::max(std::abs(x1 - x0), std::abs(y1 - y0))) + 1;
        for (int k = 0; k <= n; ++k) {
            const double t = static_cast<double>(k) / n;
            const int x = static_cast<int>(std::lround(x0 + t * (x1 - x0))), y = static_cast<int>(std::lround(y0 + t * (y1 - y0)));
            for (int dx = -thick / 2; dx <= thick / 2; ++dx)
                for (int dy = -thick / 2; dy <= thick / 2; ++dy) dot(x + dx, y + dy, c);
        }
    }
    void box(int x0, int y0, int x1, int y1, const Vec3& c) {
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) dot(x, y, c);
    }
};

const Vec3 kGauss(0.15, 0.35, 0.85), kAdaptive(0.85, 0.15, 0.15), kFaceted(0.1, 0.6, 0.2), kGrid(0.85, 0.85, 0.85),
    kAxis(0.3, 0.3, 0.3);

void write_plot(const std::vector<Config>& configs, const std::vector<Row>& rows, const fs::path& path) {
    const int cols = 3, prow = (static_cast<int>(configs.size()) + cols - 1) / cols;
    const int pw = 360, ph = 270, mx = 50, my = 30;
    Canvas cv(cols * pw, prow * ph + 60);
    const double lx0 = -6, lx1 = 2, ly0 = -14, ly1 = 0;  // log10 seconds, log10 error
    std::vector<std::pair<std::string, std::array<int, 2>>> labels;
    for (std::size_t k = 0; k < configs.size(); ++k) {
        const int ox = static_cast<int>(k % cols) * pw + mx, oy = static_cast<int>(k / cols) * ph + my;
        const int w = pw - mx - 15, h = ph - my - 30;
        auto X = [&](double s) { return ox + (std::log10(std::max(s, 1e-6)) - lx0) / (lx1 - lx0) * w; };
        auto Y = [&](double e) { return oy + h - (std::log10(std::clamp(e, 1e-14, 1.0)) - ly0) / (ly1 - ly0) * h; };
        for (int d = static_cast<int>(lx0); d <= lx1; ++d) cv.line(X(std::pow(10.0, d)), oy, X(std::pow(10.0, d)), oy + h, kGrid);
        for (int d = static_cast<int>(ly0); d <= ly1; d += 2) cv.line(ox, Y(std::pow(10.0, d)), ox + w, Y(std::pow(10.0, d)), kGrid);
        cv.line(ox, oy, ox, oy + h, kAxis);
        cv.line(ox, oy + h, ox + w, oy + h, kAxis);
        labels.push_back({configs[k].name, {ox, oy - 20}});
        for (const auto& [method, colour] : {std::pair{"gauss", kGauss}, {"adaptive", kAdaptive}, {"faceted", kFaceted}}) {
            std::vector<std::pair<double, double>> pts;
            for (const Row& r : rows)
                if (r.config == configs[k].name && r.method == method) pts.push_back({r.seconds, r.err.max});
            // In the order the method was refined (p up, tolerance down, facets up).
            for (std::size_t i = 0; i < pts.size(); ++i) {
                cv.box(static_cast<int>(X(pts[i].first)) - 2, static_cast<int>(Y(pts[i].second)) - 2,
                       static_cast<int>(X(pts[i].first)) + 2, static_cast<int>(Y(pts[i].second)) + 2, colour);
                if (i) cv.line(X(pts[i - 1].first), Y(pts[i - 1].second), X(pts[i].first), Y(pts[i].second), colour, 2);
            }
        }
    }
    // Legend swatches along the bottom.
    const int ly = prow * ph + 15;
    cv.box(20, ly, 40, ly + 10, kGauss);
    cv.box(260, ly, 280, ly + 10, kAdaptive);
    cv.box(520, ly, 540, ly + 10, kFaceted);
    OIIO::ImageBuf buf(OIIO::ImageSpec(cv.w, cv.h, 3, OIIO::TypeDesc::FLOAT), cv.rgb.data());
    OIIO::ImageBuf img;
    img.copy(buf);
    // Text needs a font (fonts-dejavu-core, installed by .ci/install-deps); without one the
    // plot is still complete and the README names the colours and axes.
    const float black[3] = {0.1f, 0.1f, 0.1f};
    const std::string font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    auto text = [&](int x, int y, const std::string& t) { OIIO::ImageBufAlgo::render_text(img, x, y, t, 14, font, black); };
    for (const auto& [t, at] : labels) text(at[0], at[1] + 12, t);
    text(48, ly + 10, "fixed Gauss p = 1..16");
    text(288, ly + 10, "adaptive, tolerance 1e-2..1e-10");
    text(548, ly + 10, "sphere as 32..2048 flat facets");
    text(20, ly + 32, "x: run time, 1e-6 .. 1e2 s; y: max error, 1e-14 .. 1; log scales, grid lines every decade (x) and two decades (y)");
    check_output_path(path);
    AtomicFile file(path);
    if (!img.write(file.temp_path().string(), OIIO::TypeDesc::UINT8))
        throw Error(path.string() + ": cannot write the plot: " + img.geterror());
    file.commit();
}

}  // namespace

void run_accuracy(const AccuracyJob& job, std::ostream& out) {
    std::error_code ec;
    fs::create_directories(job.out_dir, ec);
    if (ec) throw Error(job.out_dir + ": cannot create the output directory: " + ec.message());
    std::unique_ptr<tbb::global_control> limit;
    if (job.threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, job.threads);

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
        char buf[256];
        std::snprintf(buf, sizeof buf, "  %-40s %-9s %-8g %9.4f s  max error %.2e  mean %.2e\n", c.name.c_str(),
                      method.c_str(), param, r.seconds, r.err.max, r.err.mean);
        out << buf << std::flush;
        rows.push_back(r);
        return r.seconds;
    };
    const std::vector<int> ps = job.quick ? std::vector<int>{2} : std::vector<int>{1, 2, 3, 4, 5, 6, 8, 10, 12, 14, 16};
    const std::vector<double> tols = job.quick ? std::vector<double>{1e-3}
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
                if (run(c, c.faceted(n), "faceted", n, FormFactorOptions::adaptive(1e-9, false)) > job.budget_s) break;
    }

    const fs::path dir(job.out_dir);
    std::ostringstream csv, md;
    csv << "config,method,parameter,seconds,max_error,mean_error\n";
    md << "| configuration | method | parameter | seconds | max error | mean error |\n|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
        char buf[512];
        std::snprintf(buf, sizeof buf, "\"%s\",%s,%g,%.6g,%.6e,%.6e\n", r.config.c_str(), r.method.c_str(), r.parameter,
                      r.seconds, r.err.max, r.err.mean);
        csv << buf;
        std::snprintf(buf, sizeof buf, "| %s | %s | %g | %.4f | %.2e | %.2e |\n", r.config.c_str(), r.method.c_str(),
                      r.parameter, r.seconds, r.err.max, r.err.mean);
        md << buf;
    }
    write_text_file(dir / "accuracy.csv", csv.str());
    write_text_file(dir / "accuracy.md", md.str());
    write_plot(configs, rows, dir / "accuracy.png");
    out << "wrote " << (dir / "accuracy.csv").string() << ", " << (dir / "accuracy.md").string() << ", "
        << (dir / "accuracy.png").string() << "\n";
}

}  // namespace radiosa
