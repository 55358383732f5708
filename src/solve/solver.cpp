#include "solve/solver.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <limits>

#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Materials patch_materials(const Scene& scene, const SceneGeometry& geo) {
    Materials m;
    m.rho.resize(geo.patch_count());
    m.E.resize(geo.patch_count());
    for (int k = 0; k < geo.surface_count(); ++k) {
        const SurfaceDesc& d = scene.surfaces[k];
        for (int it = 0; it < d.nt; ++it)
            for (int is = 0; is < d.ns; ++is) {
                const int i = geo.patch_index(k, is, it);
                m.rho[i] = d.reflectance;
                m.E[i] = d.emission;
            }
        for (const auto& pe : d.patch_emission) m.E[geo.patch_index(k, pe.is, pe.it)] = pe.emission;
    }
    return m;
}

SolverMethod parse_solver_method(const std::string& name) {
    if (name == "lu") return SolverMethod::LU;
    if (name == "gauss-jordan") return SolverMethod::GaussJordan;
    throw Error("unknown solver '" + name + "' (known: lu, gauss-jordan)");
}

const char* solver_method_name(SolverMethod m) { return m == SolverMethod::LU ? "lu" : "gauss-jordan"; }

namespace {

RowMatrix system_matrix(const DenseMatrix& F, const std::vector<Rgb>& rho, int c) {
    const int n = F.n;
    RowMatrix M = -Eigen::Map<const RowMatrix>(F.data.data(), n, n);
    for (int i = 0; i < n; ++i) {
        M.row(i) *= rho[i][c];
        M(i, i) += 1.0;
    }
    return M;
}

// Gauss-Jordan elimination with partial pivoting on [M | b], as in the paper (Carnahan et
// al. 1969): reduces M to the identity, leaving x in b.
Eigen::VectorXd gauss_jordan(RowMatrix M, Eigen::VectorXd b) {
    const int n = static_cast<int>(M.rows());
    for (int col = 0; col < n; ++col) {
        int pivot = col;
        for (int r = col + 1; r < n; ++r)
            if (std::abs(M(r, col)) > std::abs(M(pivot, col))) pivot = r;
        if (M(pivot, col) == 0.0) throw Error("radiosity system is singular (Gauss-Jordan)");
        if (pivot != col) {
            M.row(col).swap(M.row(pivot));
            std::swap(b[col], b[pivot]);
        }
        const double inv = 1.0 / M(col, col);
        M.row(col) *= inv;
        b[col] *= inv;
        for (int r = 0; r < n; ++r) {
            if (r == col || M(r, col) == 0.0) continue;
            const double f = M(r, col);
            M.row(r) -= f * M.row(col);
            b[r] -= f * b[col];
        }
    }
    return b;
}

}  // namespace

struct RadiositySolver::Impl {
    SolverMethod method;
    // channel_owner[c] is the first channel with the same reflectance as channel c.
    int channel_owner[3] = {0, 1, 2};
    std::vector<Eigen::PartialPivLU<RowMatrix>> lu;  // one per distinct channel (LU only)
    std::vector<RowMatrix> systems;                  // one per distinct channel (Gauss-Jordan)
    int slot[3] = {0, 0, 0};
    std::vector<RadiositySolver::Stability> stability;  // per distinct channel
    double factorise_s = 0.0;
};

namespace {

RadiositySolver::Stability spectral_bounds(const DenseMatrix& F, const std::vector<Rgb>& rho, int c) {
    // For a non-negative matrix A and a positive vector x, min_i (Ax)_i / x_i <= rho(A) <=
    // max_i (Ax)_i / x_i; power iterations from x = 1 tighten both bounds.
    const int n = F.n;
    std::vector<double> x(n, 1.0), y(n);
    RadiositySolver::Stability s;
    for (int it = 0; it < 8; ++it) {
        double lo = std::numeric_limits<double>::infinity(), hi = 0.0, norm = 0.0;
        for (int i = 0; i < n; ++i) {
            double sum = 0.0;
            for (int j = 0; j < n; ++j) sum += F(i, j) * x[j];
            y[i] = rho[i][c] * sum;
            norm = std::max(norm, y[i]);
        }
        for (int i = 0; i < n; ++i) {
            const double r = x[i] > 0.0 ? y[i] / x[i] : 0.0;
            lo = std::min(lo, r);
            hi = std::max(hi, r);
        }
        s.spectral_lo = std::max(s.spectral_lo, lo);
        s.spectral_hi = it == 0 ? hi : std::min(s.spectral_hi, hi);
        if (!(norm > 0.0)) break;  // nothing reflects
        bool positive = true;
        for (int i = 0; i < n; ++i) {
            x[i] = y[i] / norm;
            positive = positive && x[i] > 0.0;
        }
        if (!positive) break;  // the bounds need a positive vector
    }
    return s;
}

}  // namespace

RadiositySolver::RadiositySolver(const DenseMatrix& F, const std::vector<Rgb>& rho, SolverMethod method)
    : m(std::make_unique<Impl>()) {
    const Stopwatch clock;
    m->method = method;
    int distinct = 0;
    for (int c = 0; c < 3; ++c) {
        m->channel_owner[c] = c;
        for (int d = 0; d < c; ++d) {
            bool same = true;
            for (const Rgb& r : rho) same = same && r[c] == r[d];
            if (same) {
                m->channel_owner[c] = m->channel_owner[d];
                break;
            }
        }
        if (m->channel_owner[c] != c) {
            m->slot[c] = m->slot[m->channel_owner[c]];
            continue;
        }
        m->slot[c] = distinct++;
        RowMatrix M = system_matrix(F, rho, c);
        Stability st = spectral_bounds(F, rho, c);
        if (method == SolverMethod::LU) {
            m->lu.emplace_back(M);
            const double rc = m->lu.back().rcond();
            st.condition = rc > 0.0 ? 1.0 / rc : std::numeric_limits<double>::infinity();
        } else {
            m->systems.push_back(std::move(M));
        }
        m->stability.push_back(st);
    }
    m->factorise_s = clock.seconds();
}

RadiositySolver::~RadiositySolver() = default;

int RadiositySolver::factorisations() const {
    return static_cast<int>(m->method == SolverMethod::LU ? m->lu.size() : m->systems.size());
}

double RadiositySolver::factorise_seconds() const { return m->factorise_s; }

const RadiositySolver::Stability& RadiositySolver::stability(int channel) const { return m->stability[m->slot[channel]]; }

std::string check_steady_state(const RadiositySolver& solver, const std::vector<Rgb>& rho, const std::vector<Rgb>& E,
                               bool closed, const std::string& scene_file) {
    static const char* names[3] = {"red", "green", "blue"};
    std::string warning;
    for (int c = 0; c < 3; ++c) {
        bool lit = false, all_one = true;
        for (std::size_t i = 0; i < rho.size(); ++i) {
            lit = lit || E[i][c] > 0.0;
            all_one = all_one && rho[i][c] == 1.0;
        }
        if (!lit) continue;
        const RadiositySolver::Stability& s = solver.stability(c);
        if (closed && all_one)
            throw Error(scene_file + ": every reflectance is 1 in the " + names[c] +
                        " channel of a closed scene: light is never absorbed, so radiosity grows without bound and "
                        "there is no steady state (make some reflectance < 1, or the scene open)");
        if (s.spectral_lo >= 1.0)
            throw Error(scene_file + ": the " + names[c] + " channel has no steady state: the spectral radius of rho F is " +
                        std::to_string(s.spectral_lo) + " >= 1 (reflectances too high for the form factors; lower them)");
        if (s.spectral_hi >= 0.999 - 1e-9 && warning.empty()) {
            char buf[320];
            std::snprintf(buf, sizeof buf,
                          "%s: nearly singular radiosity system in the %s channel: spectral radius of rho F in [%.6f, "
                          "%.6f], condition estimate %.1e; solved by partial-pivoting LU, expect relative error up to "
                          "~%.0e",
                          scene_file.c_str(), names[c], s.spectral_lo, s.spectral_hi, s.condition,
                          std::max(1e-16, s.condition * 1e-16));
            warning = buf;
        }
    }
    return warning;
}

std::vector<Rgb> RadiositySolver::solve(const std::vector<Rgb>& E) const {
    const int n = static_cast<int>(E.size());
    std::vector<Rgb> B(n, Rgb(0.0));
    int solved = 0;
    for (int c = 0; c < 3; ++c) {
        // A channel with the same reflectance and emission as an earlier one has its answer.
        int same = -1;
        for (int c2 = 0; c2 < c && same < 0; ++c2) {
            bool eq = m->slot[c2] == m->slot[c];
            for (int i = 0; i < n && eq; ++i) eq = E[i][c] == E[i][c2];
            if (eq) same = c2;
        }
        if (same >= 0) {
            for (int i = 0; i < n; ++i) B[i][c] = B[i][same];
            continue;
        }
        Eigen::VectorXd e(n);
        for (int i = 0; i < n; ++i) e[i] = E[i][c];
        Eigen::VectorXd x;
        if (e.isZero(0.0)) {
            x = Eigen::VectorXd::Zero(n);  // no light in this channel
        } else {
            ++solved;
            if (m->method == SolverMethod::LU) x = m->lu[m->slot[c]].solve(e);
            else x = gauss_jordan(m->systems[m->slot[c]], e);
        }
        for (int i = 0; i < n; ++i) B[i][c] = x[i];
    }
    m_last_channel_solves = solved;
    return B;
}

SolveDiagnostics diagnose_solution(const DenseMatrix& F, const std::vector<double>& area,
                                   const Materials& mat, const std::vector<Rgb>& B) {
    SolveDiagnostics d;
    const int n = F.n;
    for (int c = 0; c < 3; ++c) {
        double res2 = 0.0, e2 = 0.0, emitted = 0.0, absorbed = 0.0;
        for (int i = 0; i < n; ++i) {
            double H = 0.0;
            for (int j = 0; j < n; ++j) H += F(i, j) * B[j][c];
            const double r = B[i][c] - mat.rho[i][c] * H - mat.E[i][c];
            res2 += r * r;
            e2 += mat.E[i][c] * mat.E[i][c];
            emitted += area[i] * mat.E[i][c];
            absorbed += area[i] * (1.0 - mat.rho[i][c]) * H;
        }
        if (e2 > 0.0) d.residual = std::max(d.residual, std::sqrt(res2 / e2));
        if (emitted > 0.0)
            d.energy_balance_error = std::max(d.energy_balance_error, std::abs(emitted - absorbed) / emitted);
        d.emitted_power[c] = emitted;
        d.absorbed_power[c] = absorbed;
    }
    return d;
}

}  // namespace radiosa
