#include "solve/link_solver.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace radiosa {

namespace {

// Per node, the largest radiosity of its patches, channel by channel.
std::vector<Rgb> pull_max(const Hierarchy& h, const std::vector<Rgb>& B) {
    std::vector<Rgb> top(h.nodes.size(), Rgb(0.0));
    for (std::size_t i = h.nodes.size(); i-- > 0;) {
        const HierarchyNode& n = h.nodes[i];
        top[i] = n.leaf() ? B[static_cast<std::size_t>(n.patch)]
                          : glm::max(top[static_cast<std::size_t>(n.child[0])],
                                     top[static_cast<std::size_t>(n.child[1])]);
    }
    return top;
}

}  // namespace

SolveDiagnostics diagnose_links(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B) {
    return diagnose_links(h, m, B, h.irradiance(B));
}

SolveDiagnostics diagnose_links(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B,
                                const std::vector<Rgb>& H) {
    std::vector<double> area;
    area.reserve(B.size());
    for (const int leaf : h.leaf_of_patch) area.push_back(h.nodes[static_cast<std::size_t>(leaf)].area);
    return diagnose_irradiance(area, m, B, H);
}

Rgb link_error_estimate(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B,
                        const LinkSolveOptions& options) {
    const std::vector<Rgb> top = pull_max(h, B);
    std::vector<Rgb> node_e(h.nodes.size(), Rgb(0.0));
    h.for_each_link([&](int receiver, int source, double error) {
        node_e[static_cast<std::size_t>(receiver)] += error * top[static_cast<std::size_t>(source)];
    });
    std::vector<Rgb> e = h.to_patches(std::move(node_e));
    for (std::size_t i = 0; i < e.size(); ++i) e[i] *= m.rho[i];
    const std::vector<Rgb> d = solve_links(h, m.rho, e, options).B;
    Rgb out(0.0);
    for (int c = 0; c < 3; ++c) {
        double max_b = 0.0, max_d = 0.0;
        for (std::size_t i = 0; i < B.size(); ++i) {
            max_b = std::max(max_b, B[i][c]);
            max_d = std::max(max_d, d[i][c]);
        }
        if (max_b > 0.0) out[c] = max_d / max_b;
    }
    return out;
}

LinkSolution solve_links(const Hierarchy& h, const std::vector<Rgb>& rho, const std::vector<Rgb>& E,
                         const LinkSolveOptions& options, const std::vector<Rgb>* start) {
    LinkSolution s;
    s.B = start ? *start : E;
    const std::size_t n = E.size();
    double previous = 0.0;
    for (s.sweeps = 1; s.sweeps <= options.max_sweeps; ++s.sweeps) {
        const std::vector<Rgb> patch_h = h.irradiance(s.B);
        Rgb change(0.0), top(0.0);
        for (std::size_t i = 0; i < n; ++i) {
            const Rgb b = E[i] + rho[i] * patch_h[i];
            change = glm::max(change, glm::abs(b - s.B[i]));
            top = glm::max(top, b);
            s.B[i] = b;
        }
        s.change = 0.0;
        for (int c = 0; c < 3; ++c)
            if (top[c] > 0.0) s.change = std::max(s.change, change[c] / top[c]);
        if (s.change <= options.tolerance) return s;
        // Jacobi's change shrinks by the spectral radius of rho F per sweep: past a few dozen
        // sweeps, a rate that would need more than max_sweeps is known already.
        if (s.sweeps >= 50 && previous > 0.0 && s.change > 0.0) {
            const double rate = s.change / previous;
            if (rate >= 1.0 ||
                s.sweeps + std::log(options.tolerance / s.change) / std::log(rate) > options.max_sweeps)
                break;
        }
        previous = s.change;
    }
    throw Error("the radiosity over the hierarchy's links does not settle within " +
                std::to_string(options.max_sweeps) + " sweeps (change " + std::to_string(s.change) +
                " of the largest radiosity after " + std::to_string(s.sweeps) +
                "): reflectances too close to 1 for this scene; lower them");
}

}  // namespace radiosa
