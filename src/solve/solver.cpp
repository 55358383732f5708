#include "solve/solver.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

SolverMethod parse_solver_method(const std::string& name) {
    if (name == "lu") return SolverMethod::LU;
    if (name == "gauss-jordan") return SolverMethod::GaussJordan;
    if (name == "jacobi") return SolverMethod::Jacobi;
    if (name == "gauss-seidel") return SolverMethod::GaussSeidel;
    if (name == "southwell") return SolverMethod::Southwell;
    throw Error("unknown solver '" + name + "' (known: lu, gauss-jordan, jacobi, gauss-seidel, southwell)");
}

const char* solver_method_name(SolverMethod m) {
    switch (m) {
        case SolverMethod::LU:
            return "lu";
        case SolverMethod::GaussJordan:
            return "gauss-jordan";
        case SolverMethod::Jacobi:
            return "jacobi";
        case SolverMethod::GaussSeidel:
            return "gauss-seidel";
        case SolverMethod::Southwell:
            return "southwell";
    }
    return "?";
}

bool is_iterative(SolverMethod m) {
    return m == SolverMethod::Jacobi || m == SolverMethod::GaussSeidel || m == SolverMethod::Southwell;
}

namespace {

// Solves (I - diag(rho) F) x = e iteratively; returns sweeps used or throws at the cap.
int solve_iteratively(SolverMethod method, const DenseMatrix& F, const std::vector<double>& rho,
                      const std::vector<double>& e, const std::vector<double>* start,
                      std::vector<double>* x_out) {
    const int n = F.n;
    double e2 = 0.0;
    for (double v : e) e2 += v * v;
    const double target = kIterativeTolerance * std::sqrt(e2);
    std::vector<double>& x = *x_out;
    x = start ? *start : e;  // a warm start: the answer for nearby lights
    // The cap bounds the work (~4e9 multiply-adds), so a slow case fails instead of hanging.
    const int max_sweeps = static_cast<int>(
        std::clamp(4e9 / (static_cast<double>(n) * n), 100.0, static_cast<double>(kMaxSweeps)));
    // r = e - (I - rho F) x
    std::vector<double> r(n);
    auto residual = [&] {
        double r2 = 0.0;
        for (int i = 0; i < n; ++i) {
            double h = 0.0;
            for (int j = 0; j < n; ++j) h += F(i, j) * x[j];
            r[i] = e[i] - x[i] + rho[i] * h;
            r2 += r[i] * r[i];
        }
        return std::sqrt(r2);
    };
    if (method == SolverMethod::Southwell) {
        double norm = residual();
        const long long cap = static_cast<long long>(max_sweeps) * n;
        long long steps = 0;
        while (norm > target) {
            if (++steps > cap) break;
            int k = 0;
            for (int i = 1; i < n; ++i)
                if (std::abs(r[i]) > std::abs(r[k])) k = i;
            const double shot = r[k];  // relax patch k: its residual is shot to every patch
            x[k] += shot;
            for (int j = 0; j < n; ++j) r[j] += rho[j] * F(j, k) * shot;
            r[k] -= shot;
            if (steps % n == 0)
                norm = residual();  // recompute now and then against drift
            else {
                double r2 = 0.0;
                for (double v : r) r2 += v * v;
                norm = std::sqrt(r2);
            }
        }
        if (norm > target)
            throw Error("southwell did not converge: residual " + std::to_string(norm / std::sqrt(e2)) +
                        " after " + std::to_string(steps) +
                        " steps (spectral radius of rho F too close to 1; use --solver lu)");
        return static_cast<int>(steps / std::max(1, n));
    }
    // Jacobi reads the previous sweep's values, Gauss-Seidel the newest; both solve row i for
    // x_i, diagonal (a concave patch seeing itself) included.
    std::vector<double> next(n);
    if (start && residual() <= target) return 0;  // the start is already the answer
    for (int sweep = 1; sweep <= max_sweeps; ++sweep) {
        std::vector<double>& out = method == SolverMethod::Jacobi ? next : x;
        for (int i = 0; i < n; ++i) {
            double h = 0.0;
            for (int j = 0; j < n; ++j)
                if (j != i) h += F(i, j) * x[j];
            out[i] = (e[i] + rho[i] * h) / (1.0 - rho[i] * F(i, i));
        }
        if (method == SolverMethod::Jacobi) x.swap(next);
        if (residual() <= target) return sweep;
    }
    throw Error(std::string(solver_method_name(method)) + " did not converge: residual " +
                std::to_string(residual() / std::sqrt(e2)) + " after " + std::to_string(max_sweeps) +
                " sweeps (spectral radius of rho F too close to 1; use --solver lu)");
}

}  // namespace

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
    const DenseMatrix* F = nullptr;                     // iterative methods read it
    std::vector<std::vector<double>> rho_channel;       // per distinct channel (iterative)
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
    m->F = &F;
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
        } else if (method == SolverMethod::GaussJordan) {
            m->systems.push_back(std::move(M));
        } else {
            std::vector<double> r(rho.size());
            for (std::size_t i = 0; i < rho.size(); ++i) r[i] = rho[i][c];
            m->rho_channel.push_back(std::move(r));
        }
        m->stability.push_back(st);
    }
    m->factorise_s = clock.seconds();
}

RadiositySolver::~RadiositySolver() = default;

int RadiositySolver::factorisations() const {
    if (is_iterative(m->method)) return 0;  // nothing is factorised
    return static_cast<int>(m->method == SolverMethod::LU ? m->lu.size() : m->systems.size());
}

double RadiositySolver::factorise_seconds() const { return m->factorise_s; }

const RadiositySolver::Stability& RadiositySolver::stability(int channel) const {
    return m->stability[m->slot[channel]];
}

void StabilitySummary::add(const RadiositySolver& solver) {
    for (int c = 0; c < 3; ++c) {
        spectral_radius = std::max(spectral_radius, solver.stability(c).spectral_hi);
        condition_estimate = std::max(condition_estimate, solver.stability(c).condition);
    }
}

namespace {
const char* const kChannelNames[3] = {"red", "green", "blue"};
bool lit(const std::vector<Rgb>& E, int c) {
    return std::any_of(E.begin(), E.end(), [c](const Rgb& e) { return e[c] > 0.0; });
}
}  // namespace

void refuse_lossless(const std::vector<Rgb>& rho, const std::vector<Rgb>& E, bool closed,
                     const std::string& scene_file) {
    if (!closed) return;
    for (int c = 0; c < 3; ++c)
        if (lit(E, c) && std::all_of(rho.begin(), rho.end(), [c](const Rgb& r) { return r[c] == 1.0; }))
            throw Error(
                scene_file + ": every reflectance is 1 in the " + kChannelNames[c] +
                " channel of a closed scene: light is never absorbed, so radiosity grows without bound and "
                "there is no steady state (make some reflectance < 1, or the scene open)");
}

std::string check_steady_state(const RadiositySolver& solver, const std::vector<Rgb>& rho,
                               const std::vector<Rgb>& E, bool closed, const std::string& scene_file) {
    const char* const* names = kChannelNames;
    std::string warning;
    refuse_lossless(rho, E, closed, scene_file);
    for (int c = 0; c < 3; ++c) {
        if (!lit(E, c)) continue;
        const RadiositySolver::Stability& s = solver.stability(c);
        if (s.spectral_lo >= 1.0)
            throw Error(scene_file + ": the " + names[c] +
                        " channel has no steady state: the spectral radius of rho F is " +
                        std::to_string(s.spectral_lo) +
                        " >= 1 (reflectances too high for the form factors; lower them)");
        if (s.spectral_hi >= 0.999 - 1e-9 && warning.empty()) {
            warning = fmt::format(
                "{}: nearly singular radiosity system in the {} channel: spectral radius of rho F in "
                "[{:.6f}, "
                "{:.6f}], condition estimate {:.1e}; solved by partial-pivoting LU, expect relative error up "
                "to "
                "~{:.0e}",
                scene_file, names[c], s.spectral_lo, s.spectral_hi, s.condition,
                std::max(1e-16, s.condition * 1e-16));
        }
    }
    return warning;
}

std::vector<Rgb> RadiositySolver::solve(const std::vector<Rgb>& E, const std::vector<Rgb>* start) const {
    const int n = static_cast<int>(E.size());
    std::vector<Rgb> B(n, Rgb(0.0));
    int solved = 0, iterations = 0;
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
            if (m->method == SolverMethod::LU) {
                x = m->lu[m->slot[c]].solve(e);
            } else if (m->method == SolverMethod::GaussJordan) {
                x = gauss_jordan(m->systems[m->slot[c]], e);
            } else {
                std::vector<double> ev(e.data(), e.data() + n), xv, sv;
                if (start)
                    for (int i = 0; i < n; ++i) sv.push_back((*start)[static_cast<std::size_t>(i)][c]);
                iterations =
                    std::max(iterations, solve_iteratively(m->method, *m->F, m->rho_channel[m->slot[c]], ev,
                                                           start ? &sv : nullptr, &xv));
                x = Eigen::Map<Eigen::VectorXd>(xv.data(), n);
            }
        }
        for (int i = 0; i < n; ++i) B[i][c] = x[i];
    }
    m_last_channel_solves = solved;
    m_last_iterations = iterations;
    return B;
}

SolveDiagnostics diagnose_irradiance(const std::vector<double>& area, const Materials& mat,
                                     const std::vector<Rgb>& B, const std::vector<Rgb>& H) {
    SolveDiagnostics d;
    for (int c = 0; c < 3; ++c) {
        double res2 = 0.0, e2 = 0.0, emitted = 0.0, absorbed = 0.0;
        for (std::size_t i = 0; i < B.size(); ++i) {
            const double r = B[i][c] - mat.rho[i][c] * H[i][c] - mat.E[i][c];
            res2 += r * r;
            e2 += mat.E[i][c] * mat.E[i][c];
            emitted += area[i] * mat.E[i][c];
            absorbed += area[i] * (1.0 - mat.rho[i][c]) * H[i][c];
        }
        if (e2 > 0.0) d.residual = std::max(d.residual, std::sqrt(res2 / e2));
        if (emitted > 0.0)
            d.energy_balance_error = std::max(d.energy_balance_error, std::abs(emitted - absorbed) / emitted);
        d.emitted_power[c] = emitted;
        d.absorbed_power[c] = absorbed;
    }
    return d;
}

SolveDiagnostics diagnose_solution(const DenseMatrix& F, const std::vector<double>& area,
                                   const Materials& mat, const std::vector<Rgb>& B) {
    const int n = F.n;
    std::vector<Rgb> H(static_cast<std::size_t>(n), Rgb(0.0));
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            H[static_cast<std::size_t>(i)] += F(i, j) * B[static_cast<std::size_t>(j)];
    return diagnose_irradiance(area, mat, B, H);
}

Rgb radiosity_error_bound(const RadiositySolver& solver, const DenseMatrix& F,
                          const std::vector<double>& error, const Materials& m, const std::vector<Rgb>& B) {
    const int n = F.n;
    const std::vector<Rgb> v = solver.solve(std::vector<Rgb>(static_cast<std::size_t>(n), Rgb(1.0)));
    Rgb bound(0.0);
    for (int c = 0; c < 3; ++c) {
        double max_b = 0.0;
        for (int i = 0; i < n; ++i) max_b = std::max(max_b, std::abs(B[i][c]));
        if (!(max_b > 0.0)) continue;
        double q = 0.0, r_over_v = 0.0, v_max = 0.0;
        bool positive = true;
        for (int i = 0; i < n && positive; ++i) {
            const double vi = v[i][c];
            positive = vi > 0.0 && std::isfinite(vi);
            double mv = 0.0, eb = 0.0, fb = 0.0;
            for (int j = 0; j < n; ++j) {
                const double e = error[static_cast<std::size_t>(i) * n + j];
                mv += (F(i, j) + e) * v[j][c];
                eb += e * std::abs(B[j][c]);
                fb += F(i, j) * B[j][c];
            }
            const double rho = m.rho[i][c];
            const double r = std::abs(B[i][c] - rho * fb - m.E[i][c]) + rho * eb;
            // Rounding in the products above, so that q is not understated.
            q = std::max(q, rho * mv * (1.0 + 4.0 * n * std::numeric_limits<double>::epsilon()) / vi);
            r_over_v = std::max(r_over_v, r / vi);
            v_max = std::max(v_max, vi);
        }
        bound[c] = positive && q < 1.0 ? r_over_v / (1.0 - q) * v_max / max_b
                                       : std::numeric_limits<double>::infinity();
    }
    return bound;
}

}  // namespace radiosa
