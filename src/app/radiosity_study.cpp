#include "app/radiosity_study.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <vector>

#include "cache/cache_file.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "solve/solver.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

// max over channels of max_i |B_i - R_i| / max_i R_i (the scale radiosity_error_bound uses).
double relative_error(const std::vector<Rgb>& B, const std::vector<Rgb>& R) {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
        double top = 0.0, diff = 0.0;
        for (std::size_t i = 0; i < R.size(); ++i) {
            top = std::max(top, std::abs(R[i][c]));
            diff = std::max(diff, std::abs(B[i][c] - R[i][c]));
        }
        if (top > 0.0) worst = std::max(worst, diff / top);
    }
    return worst;
}

double worst_channel(const Rgb& b) { return std::max({b.r, b.g, b.b}); }

struct Case {
    std::string name;
    Materials mat;
    std::vector<Rgb> reference;
    double reference_bound = 0.0;
};

struct Row {
    std::string scene, method;
    double setting, form_factors_s, solve_s, error, bound;
};

// radiosity.csv (every measurement) and radiosity.md (the table docs/accuracy.md shows).
void write_tables(const fs::path& dir, const std::vector<Row>& rows, const std::vector<Case>& cases,
                  double reference_tol) {
    std::ostringstream csv, md;
    csv << "scene,method,setting,form_factors_s,solve_s,total_s,error,bound,reference_bound\n";
    md << fmt::format(
        "Reference: the same scenes with form factors at tolerance {:g}; its own bound is {:.1e} (seed) and "
        "{:.1e} (stiff): errors below it are not resolved.\n\n",
        reference_tol, cases[0].reference_bound, cases[1].reference_bound);
    md << "| scene | method | setting | form factors + solve | max \\|B − B_ref\\| / max B | reported bound "
          "| bound "
          "covers it |\n|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
        const double ref_bound = r.scene == "seed" ? cases[0].reference_bound : cases[1].reference_bound;
        csv << fmt::format("{},{},{:g},{:.6g},{:.6g},{:.6g},{:.6e},{},{:.6e}\n", r.scene, r.method, r.setting,
                           r.form_factors_s, r.solve_s, r.form_factors_s + r.solve_s, r.error,
                           r.bound < 0 ? std::string("") : fmt::format("{:.6e}", r.bound), ref_bound);
        const std::string covers = r.bound < 0                      ? "(no estimates)"
                                   : r.error <= r.bound + ref_bound ? "yes"
                                                                    : "**no**";
        md << fmt::format(
            "| {} | {} | {} | {:.3f} s | {:.2e} | {} | {} |\n", r.scene,
            r.method == "gauss" ? "fixed Gauss" : "adaptive",
            r.method == "gauss" ? fmt::format("p = {:g}", r.setting) : fmt::format("{:g}", r.setting),
            r.form_factors_s + r.solve_s, r.error,
            r.bound < 0 ? std::string("–") : fmt::format("{:.2e}", r.bound), covers);
    }
    write_text_file(dir / "radiosity.csv", csv.str());
    write_text_file(dir / "radiosity.md", md.str());
}

}  // namespace

void run_radiosity_study(const RadiosityStudyJob& job, std::ostream& out) {
    std::error_code ec;
    fs::create_directories(job.out_dir, ec);
    if (ec) throw Error(job.out_dir + ": cannot create the output directory: " + ec.message());
    const Scene seed = load_scene(job.scene), stiff = load_scene(job.stiff_scene);
    // One geometry, two sets of reflectances: every matrix serves both scenes.
    if (!(form_factor_key(seed, FormFactorOptions{}) == form_factor_key(stiff, FormFactorOptions{})))
        throw Error(job.stiff_scene + ": its geometry differs from " + job.scene +
                    "'s; the study needs the same one");
    const SceneGeometry geometry(seed);

    const double reference_tol = job.quick ? 1e-8 : 1e-11;
    out << fmt::format("reference: form factors at tolerance {:g} ...\n", reference_tol) << std::flush;
    const FormFactors ref = compute_form_factors(geometry, FormFactorOptions::adaptive(reference_tol));
    std::vector<Case> cases;
    for (const auto& [name, scene] :
         {std::pair{std::string("seed"), &seed}, std::pair{std::string("stiff"), &stiff}}) {
        Case c{name, patch_materials(*scene), {}, 0.0};
        const RadiositySolver solver(ref.F, c.mat.rho, SolverMethod::LU);
        c.reference = solver.solve(c.mat.E);
        c.reference_bound =
            worst_channel(radiosity_error_bound(solver, ref.F, ref.error, c.mat, c.reference));
        cases.push_back(std::move(c));
    }

    std::vector<Row> rows;
    auto run = [&](const std::string& method, double setting, const FormFactorOptions& o) {
        const Stopwatch ff_clock;
        const FormFactors ff = compute_form_factors(geometry, o);
        const double ff_s = ff_clock.seconds();
        for (const Case& c : cases) {
            const Stopwatch clock;
            const RadiositySolver solver(ff.F, c.mat.rho, SolverMethod::LU);
            const std::vector<Rgb> B = solver.solve(c.mat.E);
            const double solve_s = clock.seconds();
            const double bound = ff.error.empty()
                                     ? -1.0
                                     : worst_channel(radiosity_error_bound(solver, ff.F, ff.error, c.mat, B));
            rows.push_back({c.name, method, setting, ff_s, solve_s, relative_error(B, c.reference), bound});
            out << fmt::format("  {:<6} {:<9} {:<8} {:8.3f} s  error {:.2e}  bound {}\n", c.name, method,
                               fmt::format("{:g}", setting), ff_s + solve_s, rows.back().error,
                               bound < 0 ? std::string("-") : fmt::format("{:.2e}", bound))
                << std::flush;
        }
    };
    const std::vector<int> ps = job.quick ? std::vector<int>{2, 4} : std::vector<int>{2, 3, 4, 6, 8, 12};
    const std::vector<double> tols = job.quick
                                         ? std::vector<double>{1e-3, 1e-5}
                                         : std::vector<double>{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9};
    for (int p : ps) run("gauss", p, FormFactorOptions::gauss(p));
    for (double t : tols) run("adaptive", t, FormFactorOptions::adaptive(t));

    const fs::path dir(job.out_dir);
    write_tables(dir, rows, cases, reference_tol);
    out << "wrote " << (dir / "radiosity.csv").string() << " and " << (dir / "radiosity.md").string()
        << " (plot them with tools/plot-radiosity)\n";
}

}  // namespace radiosa
