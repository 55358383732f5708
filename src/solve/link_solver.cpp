#include "solve/link_solver.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "util/error.h"

namespace radiosa {

namespace {

// Area-averaged radiosity of every node, from the patches' (children come after parents).
void pull(const Hierarchy& h, const std::vector<Rgb>& B, std::vector<Rgb>* node_b) {
    node_b->assign(h.nodes.size(), Rgb(0.0));
    for (std::size_t i = h.nodes.size(); i-- > 0;) {
        const HierarchyNode& n = h.nodes[i];
        if (n.leaf()) {
            (*node_b)[i] = B[static_cast<std::size_t>(n.patch)];
            continue;
        }
        Rgb sum(0.0);
        for (const int c : n.child)
            sum += h.nodes[static_cast<std::size_t>(c)].area * (*node_b)[static_cast<std::size_t>(c)];
        (*node_b)[i] = sum / n.area;
    }
}

// Gathered at every node, then pushed down: the irradiance each patch receives.
void gather_push(const Hierarchy& h, const std::vector<Rgb>& node_b, std::vector<Rgb>* node_h,
                 std::vector<Rgb>* patch_h) {
    node_h->assign(h.nodes.size(), Rgb(0.0));
    tbb::parallel_for(std::size_t{0}, h.nodes.size(), [&](std::size_t r) {
        Rgb sum(0.0);
        for (auto l = h.first_link[r]; l < h.first_link[r + 1]; ++l) {
            const Link& k = h.links[static_cast<std::size_t>(l)];
            sum += k.f * node_b[static_cast<std::size_t>(k.source)];
        }
        (*node_h)[r] = sum;
    });
    *patch_h = h.to_patches(*node_h);
}

}  // namespace

LinkSolution solve_links(const Hierarchy& h, const std::vector<Rgb>& rho, const std::vector<Rgb>& E,
                         const LinkSolveOptions& options, const std::vector<Rgb>* start) {
    LinkSolution s;
    s.B = start ? *start : E;
    std::vector<Rgb> node_b, node_h, patch_h;
    const std::size_t n = E.size();
    for (s.sweeps = 1; s.sweeps <= options.max_sweeps; ++s.sweeps) {
        pull(h, s.B, &node_b);
        gather_push(h, node_b, &node_h, &patch_h);
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
    }
    throw Error("the radiosity over the hierarchy's links did not settle in " +
                std::to_string(options.max_sweeps) + " sweeps (last change " + std::to_string(s.change) +
                " of the largest radiosity): reflectance too close to 1 for this scene");
}

}  // namespace radiosa
