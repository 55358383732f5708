#include "solve/solver.h"

#include <Eigen/Dense>
#include <cmath>

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
    double factorise_s = 0.0;
};

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
        if (method == SolverMethod::LU) m->lu.emplace_back(M);
        else m->systems.push_back(std::move(M));
    }
    m->factorise_s = clock.seconds();
}

RadiositySolver::~RadiositySolver() = default;

int RadiositySolver::factorisations() const {
    return static_cast<int>(m->method == SolverMethod::LU ? m->lu.size() : m->systems.size());
}

double RadiositySolver::factorise_seconds() const { return m->factorise_s; }

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
