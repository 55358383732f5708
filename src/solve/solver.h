#pragma once
// Radiosity solve, one colour channel at a time: (I - diag(rho) F) B = E.
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "util/dense_matrix.h"
#include "util/math.h"

namespace radiosa {

enum class SolverMethod {
    LU,           // Eigen partial-pivoting LU; factorisation kept, a new E costs a substitution
    GaussJordan,  // the 1991 paper's method, a full elimination per channel and per E
    // Iterative, no factorisation: sweep until the residual ||(I - rho F) B - E|| / ||E|| is
    // below kIterativeTolerance, or fail (Error) at the iteration cap: never a half-converged
    // answer. They read the matrix F given to the constructor, which must outlive the solver.
    Jacobi,
    GaussSeidel,
    Southwell  // relax the patch with the largest residual each step (progressive refinement)
};
inline constexpr double kIterativeTolerance = 1e-12;
inline constexpr int kMaxSweeps =
    100000;  // sweep cap (lower for large N: ~4e9 multiply-adds); Southwell: x N steps
SolverMethod parse_solver_method(
    const std::string& name);  // lu | gauss-jordan | jacobi | gauss-seidel | southwell
const char* solver_method_name(SolverMethod m);

// Jacobi, Gauss-Seidel, Southwell: no factorisation; a start vector helps.
bool is_iterative(SolverMethod m);

class RadiositySolver {
public:
    RadiositySolver(const DenseMatrix& F, const std::vector<Rgb>& rho, SolverMethod method);
    ~RadiositySolver();
    RadiositySolver(const RadiositySolver&) = delete;
    RadiositySolver& operator=(const RadiositySolver&) = delete;

    // `start`: for the iterative methods, the first iterate (a warm start: the radiosities for
    // nearby lights); the direct methods ignore it. Same stopping rule either way.
    std::vector<Rgb> solve(const std::vector<Rgb>& E, const std::vector<Rgb>* start = nullptr) const;

    // Channels with identical reflectance share one factorisation.
    int factorisations() const;
    // Stability of (I - diag(rho_c) F) for colour channel c: bounds on the spectral radius of
    // diag(rho_c) F (Collatz-Wielandt, tightened by a few power iterations; the system has a
    // non-negative steady state only when it is below 1) and, for LU, an estimate of the
    // 1-norm condition number (0 when not estimated).
    struct Stability {
        double spectral_lo = 0.0, spectral_hi = 0.0, condition = 0.0;
    };
    const Stability& stability(int channel) const;
    // Substitutions (or eliminations) the last solve() ran: channels with identical
    // reflectance and emission, and dark channels, need none of their own.
    int last_channel_solves() const { return m_last_channel_solves; }
    // Sweeps (Southwell: relaxation steps / N) the last solve() needed, max over channels (0 for direct
    // methods).
    int last_iterations() const { return m_last_iterations; }
    double factorise_seconds() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m;
    mutable int m_last_channel_solves = 0;
    mutable int m_last_iterations = 0;
};

// The worst stability figures over the solvers a run builds (one per reflectance set): the
// spectral-radius bound of rho F and the LU condition estimate (0: none), max over channels.
struct StabilitySummary {
    double spectral_radius = 0.0;
    double condition_estimate = 0.0;
    void add(const RadiositySolver& solver);
};

// Refuses (throws Error naming `scene_file`) a lit channel with reflectance 1 on every patch of
// a closed scene: no steady state, whatever the form factors (check_steady_state's first test).
void refuse_lossless(const std::vector<Rgb>& rho, const std::vector<Rgb>& E, bool closed,
                     const std::string& scene_file);

// Refuses (throws Error naming `scene_file`) a system without a steady state — reflectance 1
// in every patch of a closed scene for a lit channel, or a spectral radius of rho F at or above
// 1 — and returns a one-line warning, or "", when it is nearly singular (spectral radius
// >= 0.999: radiosity amplifies emission 1000-fold or more and round-off with it).
std::string check_steady_state(const RadiositySolver& solver, const std::vector<Rgb>& rho,
                               const std::vector<Rgb>& E, bool closed, const std::string& scene_file);

struct SolveDiagnostics {
    // max over channels of ||(I - rho F) B - E|| / ||E|| (0 when E = 0)
    double residual = 0.0;
    // Power emitted sum A_i E_i against power absorbed sum A_i (1 - rho_i) H_i, H = F B the
    // irradiance; max over channels of |emitted - absorbed| / emitted. Meaningful for
    // closed scenes only.
    double energy_balance_error = 0.0;
    Rgb emitted_power{0.0};
    Rgb absorbed_power{0.0};
};

// An a-posteriori bound on the radiosity's error, per channel: max_i |B_i - B*_i| / max_i B_i,
// B* the solution with the exact form factors, given per-entry bounds |F_ij - F*_ij| <= error_ij
// (the form-factor estimates; FormFactors::error). With r_i = |residual_i| + rho_i sum_j
// error_ij |B_j| and v = (I - rho F)^-1 1 from the solver, if rho (F + error) v <= q v with q < 1
// then |B - B*| <= max_i (r_i / v_i) / (1 - q) * v. Infinity for a channel where no q < 1 is
// found (the system is too close to singular for the estimates); 0 for a dark channel.
Rgb radiosity_error_bound(const RadiositySolver& solver, const DenseMatrix& F,
                          const std::vector<double>& error, const Materials& m, const std::vector<Rgb>& B);

SolveDiagnostics diagnose_solution(const DenseMatrix& F, const std::vector<double>& area, const Materials& m,
                                   const std::vector<Rgb>& B);
// The same from the irradiance H_i = sum_j F_ij B_j however it was gathered (a matrix, links).
SolveDiagnostics diagnose_irradiance(const std::vector<double>& area, const Materials& m,
                                     const std::vector<Rgb>& B, const std::vector<Rgb>& H);

}  // namespace radiosa
