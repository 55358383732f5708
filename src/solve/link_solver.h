#pragma once
// The radiosity solve over a hierarchy's links (formfactor/hierarchy.h): Jacobi sweeps of
// gather, push and pull (Hanrahan, Salzman & Aupperle 1991), Chebyshev-accelerated. Each sweep
// gathers, at every node, the irradiance sum f B_source over its links (B of a node: the area
// average of its patches'), pushes it down to the patches, sets B = E + rho H there, and pulls
// the averages back up. O(links + nodes) per sweep, all three channels at once, and the same
// answer for any thread count (every sum runs over a node's own links, in their sorted order).
#include <cstddef>
#include <vector>

#include "formfactor/hierarchy.h"
#include "solve/solver.h"
#include "util/math.h"

namespace radiosa {

struct LinkSolveOptions {
    // Stop when the largest change of a sweep is below tolerance x max B (per channel).
    double tolerance = 1e-10;
    int max_sweeps = 10000;
    // Chebyshev acceleration once the first sweeps have measured their rate (about half the
    // sweeps); false: plain Jacobi sweeps (for comparison).
    bool accelerate = true;
};

struct LinkSolution {
    std::vector<Rgb> B;  // per patch
    int sweeps = 0;
    double change = 0.0;  // the last sweep's max change / max B, worst channel
};

// rho and E per patch. `start`: a warm start (the radiosities for nearby lights), else E.
// Throws Error when the sweeps do not settle within max_sweeps, or as soon as their rate of
// convergence shows they would not (no steady state, or too close to none).
LinkSolution solve_links(const Hierarchy& h, const std::vector<Rgb>& rho, const std::vector<Rgb>& E,
                         const LinkSolveOptions& options = {}, const std::vector<Rgb>* start = nullptr);

// At most this many emissions are solved together (the scheduler's batch, solve_links_together).
inline constexpr std::size_t kMaxSolvedTogether = 8;

// Several emissions with the same reflectances solved by one run of sweeps: every link is read
// once per sweep for all of them, so K emissions cost less than K solves (on the 20,000-patch
// room two took 0.8 and five 0.6 of their separate solves' time). Each emission's iteration is
// exactly what solve_links would do for it alone (its own Chebyshev weights), except that the
// sweeps stop when the last of them settles. `starts[k]`: emission k's warm start (absent or null: its
// E). At most kMaxSolvedTogether emissions; the answers in their order.
std::vector<LinkSolution> solve_links_together(const Hierarchy& h, const std::vector<Rgb>& rho,
                                               const std::vector<std::vector<Rgb>>& E,
                                               const LinkSolveOptions& options = {},
                                               const std::vector<const std::vector<Rgb>*>& starts = {});
// h.irradiance(*B[k]) for each k, by one gather over the links (at most kMaxSolvedTogether).
std::vector<std::vector<Rgb>> irradiance_together(const Hierarchy& h,
                                                  const std::vector<const std::vector<Rgb>*>& B);

// Residual ||B - E - rho H|| / ||E|| and energy balance, as diagnose_solution does for a matrix.
SolveDiagnostics diagnose_links(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B);
// The same from the irradiance H = h.irradiance(B) already at hand (for a combination of
// solutions, the same combination of their irradiances: no gather over the links).
SolveDiagnostics diagnose_links(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B,
                                const std::vector<Rgb>& H);

// An estimate (not a bound) of max_i |B_i - B*_i| / max_i B_i per channel, B* the radiosity with
// exact coupling: every link's estimate times the largest radiosity under its source node, pushed
// to the patches and carried through the scene's interreflection by one more link solve
// ((I - rho F) d = rho e), to a change of at most 1e-6 of its largest value (or `options`'
// tolerance, if looser): digits enough for an estimate. 0 for a dark channel.
Rgb link_error_estimate(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B,
                        const LinkSolveOptions& options = {});
// link_error_estimate for several radiosities with the same reflectances, their solves together.
std::vector<Rgb> link_error_estimates(const Hierarchy& h, const std::vector<Rgb>& rho,
                                      const std::vector<const std::vector<Rgb>*>& B,
                                      const LinkSolveOptions& options = {});

}  // namespace radiosa
