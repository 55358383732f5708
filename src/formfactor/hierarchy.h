#pragma once
// Hierarchical form factors (Hanrahan, Salzman & Aupperle 1991): instead of the N^2 patch pairs,
// a set of links between nodes of a hierarchy over each surface's patch grid, each link one
// coupling (a factor with slopes) between two groups of patches. The scene's patches are the
// leaves, so the radiosity is still one value per patch, directly comparable with the dense path.
//
// A node covers a rectangle of its surface's patch grid; its two children halve the longer
// side. Refinement starts from every pair of surfaces (a surface with itself when it can see
// itself) and, for a pair of nodes p, q, samples the point-to-point kernel
//   K(x, y) = cos_x cos_y V(x, y) / (pi |x - y|^2)
// at m x m Gauss points of each node, V the visibility through the scene's surfaces, and from it
// the point-to-node factors F(x -> q) at p's samples and F(y -> p) at q's. Each is fitted by a
// plane in the node's parameters (u, v in [-1, 1]); a link carries the receiver's plane (its
// slopes push down to p's patches) and the source's (gathered against q's radiosity slopes,
// pulled up from its children), so what the planes leave is its error: the estimate, per unit
// of radiosity, is the receiver's residual spread (none when p is one patch), plus the source's
// residual spread times A_q / A_p (none when q is one patch), plus the coupling's own quadrature
// error (|3 x 3 - 2 x 2 points| / A_p). Both directions' estimates must be within the tolerance.
// The criterion is independent of the emission and the reflectance (the links stay valid when
// lights and colours change) and counts partial visibility (hidden samples lower some
// factors). It estimates, and does not bound, the error. A ball's shadow can fall between the
// samples, so a link between two flat nodes that only a ball can come between (an outward whole
// sphere; every other surface proven not to, some by the hull of the nodes' corners) is made only if
// the point-to-node factors past the ball, exact at the same samples (point_to_polygon), meet
// the tolerance too, and from them. A pair that a horizon crosses (some
// sample pairs face each other, some do not) is never linked: the clipped cosines are not smooth
// there. Otherwise the larger node is split. Two leaves take the dense path's error-controlled
// pair (FormFactorRows::pair), closed forms included. A pair with no visible sample is dropped
// when a proof covers it (a planar node with all of the other behind or in its plane, a node of
// an outward sphere with all of the other behind its tangent planes, a surface that cannot see
// itself), or, when every sample pair faces the other but is hidden, kept as a zero link whose
// estimate is the unoccluded factor if that is within the tolerance; otherwise it is refined.
//
// No N x N array is built: memory is O(nodes + links).
#include <cstdint>
#include <vector>

#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"

namespace radiosa {

struct HierarchyOptions {
    double tolerance = 1e-5;  // on each link's coupling, as an absolute form factor
    int samples = 3;          // Gauss points per parameter on each node (samples^4 kernel values)
    // On the receiver's misfit in each link's estimate (0: `tolerance` alone). Every link's
    // estimate within `tolerance` still leaves a patch the sum of its ancestors' links' misfits,
    // and those add up with one sign where a kernel is convex across its receivers (near the
    // edges where two walls meet): docs/scale.md, "Receiver tolerance".
    double receiver_tolerance = 0.0;
};

struct HierarchyNode {
    int surface = 0;
    int is0 = 0, is1 = 0, it0 = 0, it1 = 0;  // the patch grid's [is0, is1) x [it0, it1)
    int patch = -1;                          // a leaf's global patch index, else -1
    int child[2] = {-1, -1};
    double area = 0.0;
    // The area-weighted centroid in the node's own parameters (u, v in [-1, 1] across it): 0 on
    // a plane, off 0 where the area element varies (towards a sphere's equator).
    double cu = 0.0, cv = 0.0;
    BoundingSphere bound;
    bool leaf() const { return patch >= 0; }
};

// The receiver gathers f x (the source's area-averaged radiosity): f is the form factor from
// the receiver node (averaged over its area) to the source node.
struct Link {
    int receiver = 0, source = 0;
    double f = 0.0;
    double error = 0.0;  // estimate of |f - exact| at every point of the receiver
    // The factor's slopes over the receiver: F(x -> source) ~ f + gs u + gt v, u and v in
    // [-1, 1] across the receiver's parameter rectangle (area-weighted mean f); 0 for a patch.
    // The slopes are corrections to f and are held in single precision (40 bytes a link, not
    // 56: the links are most of a large scene's memory); their rounding is in `error`.
    float gs = 0.0f, gt = 0.0f;
    // The source's slopes: the receiver also gathers cs Bs + ct Bt, Bs and Bt the source's
    // radiosity slopes along u and v (Hierarchy::irradiance); 0 for a patch.
    float cs = 0.0f, ct = 0.0f;
};
static_assert(sizeof(Link) == 40, "a link's size is in docs/scale.md");

// A link between two patches: both ends are one patch, so it has no slopes (24 bytes, not a
// Link's 40: most of a large scene's links are these).
struct PairLink {
    int receiver = 0, source = 0;
    double f = 0.0;
    double error = 0.0;
};
static_assert(sizeof(PairLink) == 24, "a link's size is in docs/scale.md");

// The order links are held and stored in: by receiver, then source (either kind).
template <class A, class B>
bool link_before(const A& a, const B& b) {
    return a.receiver != b.receiver ? a.receiver < b.receiver : a.source < b.source;
}

struct HierarchyStats {
    long long links = 0;
    long long leaf_links = 0;  // links between two patches, by the dense path's pair integral
    long long node_pairs = 0;  // node pairs examined during refinement
    long long kernel_samples = 0;
    long long dropped = 0;  // node pairs proven (or estimated) to exchange nothing
    double seconds = 0.0;
};

struct Hierarchy {
    std::vector<HierarchyNode> nodes;  // surface roots first, in surface order
    std::vector<int> leaf_of_patch;    // node index of each patch
    std::vector<Link> links;  // with a group of patches at one end or both, sorted by (receiver, source)
    std::vector<PairLink> pair_links;           // between two patches, sorted by (receiver, source)
    std::vector<std::int64_t> first_link;       // links of node r: [first_link[r], first_link[r + 1])
    std::vector<std::int64_t> first_pair_link;  // pair links of node r, likewise
    HierarchyOptions options;
    HierarchyStats stats;
    FormFactorStats leaf_stats;  // the leaf pairs' integration counts

    int roots = 0;  // nodes[0, roots) are the surfaces' roots, nodes[k] surface k's
    // Every link, both kinds, as f(receiver, source, error).
    template <class F>
    void for_each_link(F&& f) const {
        for (const Link& l : links) f(l.receiver, l.source, l.error);
        for (const PairLink& l : pair_links) f(l.receiver, l.source, l.error);
    }
    long long link_count() const { return static_cast<long long>(links.size() + pair_links.size()); }
    // Per-node values summed down every path from a root (children come after parents), read
    // at the patches: what a patch receives through its own links and those of every node
    // above it.
    template <class T>
    std::vector<T> to_patches(std::vector<T> per_node) const {
        for (std::size_t i = 0; i < nodes.size(); ++i)
            for (const int c : nodes[i].child)
                if (c >= 0) per_node[static_cast<std::size_t>(c)] += per_node[i];
        std::vector<T> out;
        out.reserve(leaf_of_patch.size());
        for (const int leaf : leaf_of_patch) out.push_back(per_node[static_cast<std::size_t>(leaf)]);
        return out;
    }
    // Per-node values with slopes (value + hs u + ht v over the node), pushed down to the
    // patches: a child takes the parent's plane over its half, so the children's area-weighted
    // mean stays the parent's value (T: double or Rgb).
    template <class T>
    std::vector<T> push_linear(std::vector<T> h, std::vector<T> hs, std::vector<T> ht) const {
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            const HierarchyNode& n = nodes[i];
            if (n.leaf()) continue;
            const HierarchyNode& c0 = nodes[static_cast<std::size_t>(n.child[0])];
            const HierarchyNode& c1 = nodes[static_cast<std::size_t>(n.child[1])];
            const bool along_s = c0.is1 != n.is1;
            const double alpha = split_fraction(n);
            const T slope = along_s ? hs[i] : ht[i];
            const std::size_t k0 = static_cast<std::size_t>(n.child[0]),
                              k1 = static_cast<std::size_t>(n.child[1]);
            // The children's area centroids lie d apart along the split: each takes the plane's
            // mean over itself, and their area-weighted mean stays the parent's value.
            const double d = centroid_gap(n);
            h[k0] += h[i] - slope * (d * c1.area / n.area);
            h[k1] += h[i] + slope * (d * c0.area / n.area);
            (along_s ? hs : ht)[k0] += slope * alpha;
            (along_s ? hs : ht)[k1] += slope * (1.0 - alpha);
            (along_s ? ht : hs)[k0] += (along_s ? ht : hs)[i];
            (along_s ? ht : hs)[k1] += (along_s ? ht : hs)[i];
        }
        std::vector<T> out;
        out.reserve(leaf_of_patch.size());
        for (const int leaf : leaf_of_patch) out.push_back(h[static_cast<std::size_t>(leaf)]);
        return out;
    }
    // Of a split node: the share of its split side in its first child, and how far apart its
    // children's area centroids lie along the split in its (u, v) (1 when the area element is
    // uniform).
    double split_fraction(const HierarchyNode& n) const {
        const HierarchyNode& c0 = nodes[static_cast<std::size_t>(n.child[0])];
        return c0.is1 != n.is1 ? double(c0.is1 - n.is0) / (n.is1 - n.is0)
                               : double(c0.it1 - n.it0) / (n.it1 - n.it0);
    }
    double centroid_gap(const HierarchyNode& n) const {
        const HierarchyNode& c0 = nodes[static_cast<std::size_t>(n.child[0])];
        const HierarchyNode& c1 = nodes[static_cast<std::size_t>(n.child[1])];
        const bool along_s = c0.is1 != n.is1;
        const double a = split_fraction(n);
        return 1.0 + (1.0 - a) * (along_s ? c1.cu : c1.cv) - a * (along_s ? c0.cu : c0.cv);
    }
    // sum_j F_ij for every patch.
    std::vector<double> row_sums() const;
    // The irradiance each patch receives from radiosities B per patch: pull (every node's
    // area-weighted mean and its slopes along u and v from its children's), gather over the
    // links (f, the receiver's and the source's slopes), push down (push_linear).
    // T: double, Rgb, or Channels<3 K> for K = 2 to 8 right-hand sides at once.
    template <class T>
    std::vector<T> irradiance(const std::vector<T>& B) const;
};

// The patch-to-patch matrix the links stand for: column j is the irradiance (Hierarchy::
// irradiance, slopes included) from radiosity 1 on patch j alone, so F B is what the solve
// gathers; the estimate of F_ij sums each link p <- q over patch i under p and j under q as
// error A_j / A_q. O(N^2) memory and N gathers: small scenes, tests, `formfactors --matrix`.
FormFactors expand_links(const Hierarchy& h, const SceneGeometry& g);

// Memory held by the nodes, links and their index.
std::size_t hierarchy_bytes(const Hierarchy& h);

// The nodes alone (no links): what the links refer to, rebuilt from the geometry when the
// links come from the cache.
Hierarchy hierarchy_nodes(const SceneGeometry& geometry, const HierarchyOptions& options);

// Sets first_link and first_pair_link (and stats.links) from links sorted by (receiver, source).
void index_links(Hierarchy* h);

// Builds the hierarchy and its links. `leaf` sets the leaf pairs' integration (its method and
// tolerance); culling and visibility follow it. Deterministic for any thread count. `progress`
// is told the pairs of patches each finished link, leaf pair or dropped pair covers: they add
// up to N (N + 1) / 2, as the dense path's pairs do.
Hierarchy build_hierarchy(const SceneGeometry& geometry, const HierarchyOptions& options,
                          const FormFactorOptions& leaf, const PairProgress& progress = {});

// The matrix checks (form_factor.h) over the links: closure from row_sums(), reciprocity
// A_p f_pq = A_q f_qp between each link and its reverse, the smallest coupling, the largest
// estimates (per link, and summed down to each patch), and the links whose estimate misses its
// target (a pair of patches: `leaf_tolerance` x min(A_i, A_j) / A_i; a link above them:
// the hierarchy's tolerance).
FormFactorChecks check_hierarchy(const Hierarchy& h, double leaf_tolerance);

}  // namespace radiosa
