#include "app/validation_study.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <vector>

#include "formfactor/analytic.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

// One quantity with a known answer, read off a computed matrix: its value and its estimate.
struct Reading {
    double value = 0.0, estimate = 0.0;
};

struct Case {
    std::string family, parameters;
    std::string yaml;  // the scene's surfaces
    double exact = 0.0;
    std::function<Reading(const FormFactors&)> read;
};

struct Measurement {
    int config = 0;
    std::string family, parameters;
    double tolerance = 0.0, exact = 0.0, value = 0.0, estimate = 0.0, seconds = 0.0;
    bool capped = false;
    double error() const { return std::abs(value - exact); }
};

std::string v3(const Vec3& v) { return fmt::format("[{:.17g}, {:.17g}, {:.17g}]", v.x, v.y, v.z); }

std::string quad(const std::string& name, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    return fmt::format(
        "  - {{name: {}, type: quad, corners: [{}, {}, {}, {}], patches: [1, 1], reflectance: [0, 0, 0]}}\n",
        name, v3(a), v3(b), v3(c), v3(d));
}

// F_01 with its estimate.
Reading entry01(const FormFactors& ff) { return {ff.F(0, 1), ff.error[1]}; }

class Sampler {
public:
    explicit Sampler(unsigned seed) : m_rng(seed) {}
    double log_uniform(double lo, double hi) {
        return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(m_rng));
    }
    int pick(std::initializer_list<int> v) {
        return *(v.begin() + std::uniform_int_distribution<int>(0, static_cast<int>(v.size()) - 1)(m_rng));
    }

private:
    std::mt19937 m_rng;
};

// Howell C-11: opposed a x b rectangles at distance c, everything scaled by `scale`.
Case opposed(Sampler& s) {
    const double a = s.log_uniform(0.05, 20), b = s.log_uniform(0.05, 20);
    const double c = std::min(a, b) * s.log_uniform(1e-9, 10), k = s.log_uniform(1e-6, 1e6);
    return {"opposed rectangles", fmt::format("a {:.3g}, b {:.3g}, c {:.3g}, scale {:.1e}", a, b, c, k),
            quad("lo", k * Vec3(0, 0, 0), k * Vec3(a, 0, 0), k * Vec3(a, b, 0), k * Vec3(0, b, 0)) +
                quad("hi", k * Vec3(0, 0, c), k * Vec3(0, b, c), k * Vec3(a, b, c), k * Vec3(a, 0, c)),
            static_cast<double>(analytic::parallel_rectangles<long double>(a, b, c)), entry01};
}

// Howell C-14, and with a gap g between the rectangles' shared edge lines (superposition).
Case perpendicular(Sampler& s, bool gap) {
    const double l = s.log_uniform(0.05, 20), w = s.log_uniform(0.05, 20), h = s.log_uniform(0.05, 20);
    const double g = gap ? std::min({l, w, h}) * s.log_uniform(1e-9, 1) : 0.0;
    const double k = s.log_uniform(1e-6, 1e6);
    return {
        gap ? "perpendicular rectangles, gap" : "perpendicular rectangles, shared edge",
        fmt::format("l {:.3g}, w {:.3g}, h {:.3g}, gap {:.3g}, scale {:.1e}", l, w, h, g, k),
        quad("floor", k * Vec3(0, 0, 0), k * Vec3(l, 0, 0), k * Vec3(l, w, 0), k * Vec3(0, w, 0)) +
            quad("wall", k * Vec3(0, 0, g), k * Vec3(0, 0, g + h), k * Vec3(l, 0, g + h), k * Vec3(l, 0, g)),
        static_cast<double>(gap ? analytic::perpendicular_rectangles_gap<long double>(l, w, g, h)
                                : analytic::perpendicular_rectangles<long double>(l, w, h)),
        entry01};
}

// The area-weighted form factor from surface a's patches to surface b's (patch ranges [a0, a1)
// and [b0, b1) in the scene's order), with the area-weighted sum of their estimates.
Reading surface_to_surface(const FormFactors& ff, int a0, int a1, int b0, int b1) {
    Reading rd;
    double area = 0.0;
    for (int i = a0; i < a1; ++i) {
        area += ff.area[i];
        for (int j = b0; j < b1; ++j) {
            rd.value += ff.area[i] * ff.F(i, j);
            rd.estimate += ff.area[i] * ff.error[static_cast<std::size_t>(i) * ff.F.n + j];
        }
    }
    rd.value /= area;
    rd.estimate /= area;
    return rd;
}

// A sphere of radius r whose centre is at height h above a corner of an a x b rectangle:
// F(sphere -> rectangle) = atan(D1 D2 / sqrt(1 + D1^2 + D2^2)) / (4 pi), D = a/h, b/h (Howell
// B-?; a quarter of an infinite plane gives 1/8). Read as the area-weighted sum over the
// sphere's patches.
Case sphere_to_rectangle(Sampler& s) {
    const double r = s.log_uniform(0.1, 1), h = r * (1.0 + s.log_uniform(1e-3, 10));
    const double a = h * s.log_uniform(0.1, 10), b = h * s.log_uniform(0.1, 10);
    const int ns = s.pick({1, 2, 4, 8}), nt = s.pick({1, 2, 4});
    const long double D1 = static_cast<long double>(a) / h, D2 = static_cast<long double>(b) / h;
    const double exact = static_cast<double>(std::atan(D1 * D2 / std::sqrt(1 + D1 * D1 + D2 * D2)) /
                                             (4 * analytic::kPiT<long double>));
    return {
        "sphere to rectangle",
        fmt::format("r {:.3g}, h {:.3g}, a {:.3g}, b {:.3g}, patches {}x{}", r, h, a, b, ns, nt),
        quad("rect", Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a, b, 0), Vec3(0, b, 0)) +
            fmt::format("  - {{name: ball, type: sphere, center: [0, 0, {:.17g}], radius: {:.17g}, patches: "
                        "[{}, {}], reflectance: [0, 0, 0]}}\n",
                        h, r, ns, nt),
        exact, [](const FormFactors& ff) { return surface_to_surface(ff, 1, ff.F.n, 0, 1); }};
}

// Two parallel unit squares at distance c with a rectangular plate between them at height h:
// the semi-closed reference of analytic::parallel_squares_with_plate.
Case plate_between_squares(Sampler& s) {
    const double c = s.log_uniform(0.1, 3), h = c * s.log_uniform(0.1, 0.9);
    const double w = s.log_uniform(0.05, 1), d = s.log_uniform(0.05, 1);
    const double x0 = -0.5 + 1.5 * s.log_uniform(1e-3, 1), y0 = -0.5 + 1.5 * s.log_uniform(1e-3, 1);
    return {
        "parallel squares with a plate between",
        fmt::format("c {:.3g}, h {:.3g}, plate [{:.3g}, {:.3g}] x [{:.3g}, {:.3g}]", c, h, x0, x0 + w, y0,
                    y0 + d),
        quad("lower", Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)) +
            quad("upper", Vec3(0, 0, c), Vec3(0, 1, c), Vec3(1, 1, c), Vec3(1, 0, c)) +
            quad("plate", Vec3(x0, y0, h), Vec3(x0 + w, y0, h), Vec3(x0 + w, y0 + d, h), Vec3(x0, y0 + d, h)),
        analytic::parallel_squares_with_plate(c, h, x0, x0 + w, y0, y0 + d), entry01};
}

// The inside of a sphere: every entry is A_j / (4 pi R^2); read the worst entry's error.
Case inside_sphere(Sampler& s) {
    const double r = s.log_uniform(1e-6, 1e6);
    const int ns = s.pick({2, 4, 8}), nt = s.pick({1, 2, 4});
    return {
        "inside of a sphere", fmt::format("R {:.3g}, patches {}x{}", r, ns, nt),
        fmt::format("  - {{name: shell, type: sphere, center: [0, 0, 0], radius: {:.17g}, facing: inward, "
                    "patches: [{}, {}], reflectance: [0, 0, 0]}}\n",
                    r, ns, nt),
        0.0, [](const FormFactors& ff) {
            Reading rd;
            const int n = ff.F.n;
            double total = 0.0;
            for (double a : ff.area) total += a;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const double err = std::abs(ff.F(i, j) - ff.area[j] / total);
                    if (err >= rd.value) rd = {err, ff.error[static_cast<std::size_t>(i) * n + j]};
                }
            return rd;
        }};
}

std::string disk(const std::string& name, double z, double nz, double radius, int around, int radial,
                 double k) {
    return fmt::format(
        "  - {{name: {}, type: disk, center: [0, 0, {:.17g}], normal: [0, 0, {}], radius: {:.17g}, patches: "
        "[{}, "
        "{}], reflectance: [0, 0, 0]}}\n",
        name, k * z, nz, k * radius, around, radial);
}

Case coaxial(Sampler& s) {
    const double r1 = s.log_uniform(0.05, 20), r2 = s.log_uniform(0.05, 20);
    const double h = std::min(r1, r2) * s.log_uniform(1e-9, 10), k = s.log_uniform(1e-6, 1e6);
    const int a1 = s.pick({1, 2, 4}), n1 = s.pick({1, 2}), a2 = s.pick({1, 2, 4}), n2 = s.pick({1, 2});
    const int p1 = a1 * n1, p2 = a2 * n2;
    return {"coaxial disks",
            fmt::format("r1 {:.3g}, r2 {:.3g}, h {:.3g}, scale {:.1e}, patches {}x{} and {}x{}", r1, r2, h, k,
                        a1, n1, a2, n2),
            disk("lo", 0, 1, r1, a1, n1, k) + disk("hi", h, -1, r2, a2, n2, k),
            static_cast<double>(analytic::coaxial_disks<long double>(r1, r2, h)),
            [p1, p2](const FormFactors& ff) { return surface_to_surface(ff, 0, p1, p1, p1 + p2); }};
}

// A ball of radius r whose centre is at height h above the centre of a disk of radius a:
// F(ball -> disk) = (1 - 1 / sqrt(1 + (a / h)^2)) / 2 for any r < h (Howell's sphere to coaxial
// disk), read as the area-weighted sum over the ball's patches.
Case ball_over_disk(Sampler& s) {
    const double r = s.log_uniform(0.1, 1), h = r * (1.0 + s.log_uniform(1e-3, 10));
    const double a = h * s.log_uniform(0.1, 10), k = s.log_uniform(1e-6, 1e6);
    const int ns = s.pick({2, 4, 8}), nt = s.pick({1, 2, 4}), around = s.pick({1, 2, 4}),
              radial = s.pick({1, 2});
    const long double R = static_cast<long double>(a) / h;
    const int nd = around * radial;
    return {
        "ball over a coaxial disk",
        fmt::format("r {:.3g}, h {:.3g}, a {:.3g}, scale {:.1e}, patches {}x{} and {}x{}", r, h, a, k, ns, nt,
                    around, radial),
        disk("disk", 0, 1, a, around, radial, k) +
            fmt::format("  - {{name: ball, type: sphere, center: [0, 0, {:.17g}], radius: {:.17g}, patches: "
                        "[{}, {}], reflectance: [0, 0, 0]}}\n",
                        k * h, k * r, ns, nt),
        static_cast<double>((1 - 1 / std::sqrt(1 + R * R)) / 2),
        [nd, ns, nt](const FormFactors& ff) { return surface_to_surface(ff, nd, nd + ns * nt, 0, nd); }};
}

// The inside of a closed frustum (top radius 0: a pointed cone) on its base disk, with a lid on
// a frustum: what the base sends the side is 1 - F(base -> lid) (Howell C-41), all of it for a
// pointed cone.
Case closed_cone(Sampler& s) {
    const double r0 = s.log_uniform(0.05, 20), l = r0 * s.log_uniform(0.05, 20), k = s.log_uniform(1e-6, 1e6);
    const double r1 = s.pick({0, 1}) == 0 ? 0.0 : r0 * s.log_uniform(0.05, 20);
    const int around = s.pick({2, 4, 8}), along = s.pick({1, 2, 3}), lid_around = s.pick({1, 2, 4});
    const int nb = lid_around, nl = r1 > 0.0 ? lid_around : 0;
    std::string yaml = disk("base", 0, 1, r0, lid_around, 1, k);
    if (r1 > 0.0) yaml += disk("lid", l, -1, r1, lid_around, 1, k);
    yaml += fmt::format(
        "  - {{name: side, type: cone, base: [0, 0, 0], axis: [0, 0, {:.17g}], radius: {:.17g}, top_radius: "
        "{:.17g}, facing: inward, patches: [{}, {}], reflectance: [0, 0, 0]}}\n",
        k * l, k * r0, k * r1, around, along);
    return {r1 > 0.0 ? "closed frustum" : "closed cone",
            fmt::format("r0 {:.3g}, r1 {:.3g}, l {:.3g}, scale {:.1e}, patches {}x{}", r0, r1, l, k, around,
                        along),
            yaml, r1 > 0.0 ? static_cast<double>(1 - analytic::coaxial_disks<long double>(r0, r1, l)) : 1.0,
            [nb, nl, around, along](const FormFactors& ff) {
                return surface_to_surface(ff, 0, nb, nb + nl, nb + nl + around * along);
            }};
}

std::vector<Case> cases(const ValidationJob& job) {
    Sampler s(job.seed);
    std::vector<Case> c;
    for (int k = 0; k < job.per_family; ++k) {
        c.push_back(opposed(s));
        c.push_back(perpendicular(s, false));
        c.push_back(perpendicular(s, true));
        c.push_back(sphere_to_rectangle(s));
        c.push_back(plate_between_squares(s));
        if (k % 5 == 0) c.push_back(inside_sphere(s));
    }
    // The curved types' families, drawn from a second stream so that the ones above keep their
    // configurations (and halves) as they were.
    Sampler t(job.seed + 1);
    for (int k = 0; k < job.per_family; ++k) {
        c.push_back(coaxial(t));
        c.push_back(ball_over_disk(t));
        c.push_back(closed_cone(t));
    }
    return c;
}

const std::vector<double> kTolerances = {1e-4, 1e-6, 1e-8, 1e-10};

std::vector<Measurement> measure(const std::vector<Case>& all) {
    std::vector<Measurement> ms;
    for (std::size_t k = 0; k < all.size(); ++k) {
        const Case& c = all[k];
        const Scene scene = parse_scene("closed: false\nsurfaces:\n" + c.yaml, "validation");
        const SceneGeometry g(scene);
        for (double tol : kTolerances) {
            const FormFactors ff = compute_form_factors(g, FormFactorOptions::adaptive(tol));
            const Reading rd = c.read(ff);
            ms.push_back({static_cast<int>(k), c.family, c.parameters, tol, c.exact, rd.value, rd.estimate,
                          ff.stats.seconds, ff.stats.capped > 0});
        }
    }
    return ms;
}

// Even configurations fit, odd ones check; measurements of one configuration are consecutive,
// in kTolerances' order.
ValidationSummary summarise(const std::vector<Measurement>& ms) {
    ValidationSummary sum;
    sum.measurements = static_cast<int>(ms.size());
    for (std::size_t k = 0; k < ms.size(); ++k) {
        const Measurement& m = ms[k];
        if (m.config % 2 == 0) {
            if (m.error() > 0.0)
                sum.fit_needed_factor =
                    std::max(sum.fit_needed_factor, m.estimate > 0.0 ? m.error() / m.estimate : INFINITY);
            continue;
        }
        ++sum.check_measurements;
        sum.check_covered += m.error() <= m.estimate;
        if (!m.capped) {
            ++sum.check_uncapped;
            sum.check_within_tolerance += m.error() <= m.tolerance;
        }
        if (k > 0 && ms[k - 1].config == m.config) {
            ++sum.check_pairs;
            // Tighter is no worse: the error at the tighter tolerance stays within that
            // tolerance or below the looser one's error.
            sum.check_monotone += m.error() <= std::max(ms[k - 1].error(), m.tolerance);
        }
    }
    return sum;
}

std::string csv_of(const std::vector<Measurement>& ms) {
    std::string csv = "config,half,family,parameters,tolerance,exact,value,error,estimate,capped,seconds\n";
    for (const Measurement& m : ms)
        csv += fmt::format("{},{},\"{}\",\"{}\",{:g},{:.17g},{:.17g},{:.3e},{:.3e},{},{:.4f}\n", m.config,
                           m.config % 2 == 0 ? "fit" : "check", m.family, m.parameters, m.tolerance, m.exact,
                           m.value, m.error(), m.estimate, m.capped ? 1 : 0, m.seconds);
    return csv;
}

std::string markdown_of(const ValidationJob& job, const ValidationSummary& sum,
                        const std::vector<Measurement>& ms) {
    std::string md = fmt::format("| | |\n|---|---|\n| configurations | {} (seed {}, {} per family) |\n",
                                 sum.configurations, job.seed, job.per_family);
    md += fmt::format("| measurements | {} (tolerances 1e-4, 1e-6, 1e-8, 1e-10) |\n", sum.measurements);
    md += fmt::format(
        "| fitting half: largest error / estimate | {:.3g} (1 or less: no extra safety needed) |\n",
        sum.fit_needed_factor);
    md += fmt::format("| checking half: error within its estimate | {} of {} |\n", sum.check_covered,
                      sum.check_measurements);
    md += fmt::format("| checking half: uncapped and within tolerance | {} of {} |\n",
                      sum.check_within_tolerance, sum.check_uncapped);
    md += fmt::format("| checking half: tighter tolerance no worse | {} of {} |\n", sum.check_monotone,
                      sum.check_pairs);
    md +=
        "\n| family | tolerance | measurements | max error | max error / estimate | max seconds |\n"
        "|---|---|---|---|---|---|\n";
    std::vector<std::string> families;
    for (const Measurement& m : ms)
        if (std::find(families.begin(), families.end(), m.family) == families.end())
            families.push_back(m.family);
    for (const std::string& f : families)
        for (double tol : kTolerances) {
            int count = 0;
            double worst = 0.0, ratio = 0.0, secs = 0.0;
            for (const Measurement& m : ms)
                if (m.family == f && m.tolerance == tol) {
                    ++count;
                    worst = std::max(worst, m.error());
                    ratio = std::max(
                        ratio, m.estimate > 0 ? m.error() / m.estimate : (m.error() > 0 ? INFINITY : 0));
                    secs = std::max(secs, m.seconds);
                }
            md += fmt::format("| {} | {:g} | {} | {:.2e} | {:.3g} | {:.3f} |\n", f, tol, count, worst, ratio,
                              secs);
        }
    return md;
}

}  // namespace

ValidationSummary run_validation(const ValidationJob& job, std::ostream& out) {
    std::error_code ec;
    fs::create_directories(job.out_dir, ec);
    if (ec) throw Error(job.out_dir + ": cannot create the output directory: " + ec.message());
    const std::vector<Case> all = cases(job);
    const std::vector<Measurement> ms = measure(all);
    ValidationSummary sum = summarise(ms);
    sum.configurations = static_cast<int>(all.size());
    const std::string md = markdown_of(job, sum, ms);
    const fs::path dir(job.out_dir);
    write_text_file(dir / "validation.csv", csv_of(ms));
    write_text_file(dir / "validation.md", md);
    out << md << "wrote " << (dir / "validation.csv").string() << " and " << (dir / "validation.md").string()
        << "\n";
    return sum;
}

}  // namespace radiosa
