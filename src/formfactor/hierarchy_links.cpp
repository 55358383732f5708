// What works on built links: the gather (pull, links, push), row sums, the dense expansion,
// the checks and the link index (formfactor/hierarchy.h).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "formfactor/hierarchy.h"
#include "util/channels.h"

namespace radiosa {
namespace {

template <class T>
std::vector<T> irradiance_of(const Hierarchy& h, const std::vector<T>& B) {
    const std::size_t n = h.nodes.size();
    std::vector<T> b(n, T(0.0)), bs(n, T(0.0)), bt(n, T(0.0));
    for (std::size_t i = n; i-- > 0;) {  // pull: children come after their parent
        const HierarchyNode& d = h.nodes[i];
        if (d.leaf()) {
            b[i] = B[static_cast<std::size_t>(d.patch)];
            continue;
        }
        const std::size_t k0 = static_cast<std::size_t>(d.child[0]),
                          k1 = static_cast<std::size_t>(d.child[1]);
        const double a0 = h.nodes[k0].area / d.area, a1 = h.nodes[k1].area / d.area;
        b[i] = a0 * b[k0] + a1 * b[k1];
        // The halves' area centroids lie centroid_gap apart in the node's u (or v).
        const bool along_s = h.nodes[k0].is1 != d.is1;
        (along_s ? bs : bt)[i] = (b[k1] - b[k0]) / h.centroid_gap(d);
        (along_s ? bt : bs)[i] = a0 * (along_s ? bt : bs)[k0] + a1 * (along_s ? bt : bs)[k1];
    }
    std::vector<T> hh(n, T(0.0)), hs(n, T(0.0)), ht(n, T(0.0));
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t r) {
        T sum(0.0), ss(0.0), st(0.0);
        for (auto l = h.first_link[r]; l < h.first_link[r + 1]; ++l) {
            const Link& k = h.links[static_cast<std::size_t>(l)];
            const std::size_t q = static_cast<std::size_t>(k.source);
            sum += k.f * b[q] + double(k.cs) * bs[q] + double(k.ct) * bt[q];
            ss += double(k.gs) * b[q];
            st += double(k.gt) * b[q];
        }
        for (auto l = h.first_pair_link[r]; l < h.first_pair_link[r + 1]; ++l) {
            const PairLink& k = h.pair_links[static_cast<std::size_t>(l)];
            sum += k.f * b[static_cast<std::size_t>(k.source)];
        }
        hh[r] = sum, hs[r] = ss, ht[r] = st;
    });
    return h.push_linear(std::move(hh), std::move(hs), std::move(ht));
}

}  // namespace

template <class T>
std::vector<T> Hierarchy::irradiance(const std::vector<T>& B) const {
    return irradiance_of(*this, B);
}
template std::vector<double> Hierarchy::irradiance(const std::vector<double>&) const;
template std::vector<Rgb> Hierarchy::irradiance(const std::vector<Rgb>&) const;
template std::vector<Channels<6>> Hierarchy::irradiance(const std::vector<Channels<6>>&) const;
template std::vector<Channels<9>> Hierarchy::irradiance(const std::vector<Channels<9>>&) const;
template std::vector<Channels<12>> Hierarchy::irradiance(const std::vector<Channels<12>>&) const;
template std::vector<Channels<15>> Hierarchy::irradiance(const std::vector<Channels<15>>&) const;
template std::vector<Channels<18>> Hierarchy::irradiance(const std::vector<Channels<18>>&) const;
template std::vector<Channels<21>> Hierarchy::irradiance(const std::vector<Channels<21>>&) const;
template std::vector<Channels<24>> Hierarchy::irradiance(const std::vector<Channels<24>>&) const;

std::vector<double> Hierarchy::row_sums() const {
    return irradiance(std::vector<double>(leaf_of_patch.size(), 1.0));
}

FormFactors expand_links(const Hierarchy& h, const SceneGeometry& g) {
    const int n = g.patch_count();
    const std::size_t un = static_cast<std::size_t>(n);
    FormFactors ff;
    ff.F = DenseMatrix(n);
    ff.error.assign(un * un, 0.0);
    for (int i = 0; i < n; ++i) ff.area.push_back(g.patch(i).area);
    // Column j: the irradiance from radiosity 1 on patch j alone, as the solve gathers it.
    std::vector<double> unit(un, 0.0);
    for (std::size_t j = 0; j < un; ++j) {
        unit[j] = 1.0;
        const std::vector<double> column = h.irradiance(unit);
        unit[j] = 0.0;
        for (std::size_t i = 0; i < un; ++i) ff.F.data[i * un + j] = column[i];
    }
    // Estimates: each link's, shared by area among its source's patches, at each receiver patch.
    const auto patches = [&](const HierarchyNode& a) {
        std::vector<int> out;
        for (int it = a.it0; it < a.it1; ++it)
            for (int is = a.is0; is < a.is1; ++is) out.push_back(g.patch_index(a.surface, is, it));
        return out;
    };
    h.for_each_link([&](int receiver, int source, double error) {
        const HierarchyNode& q = h.nodes[static_cast<std::size_t>(source)];
        const std::vector<int> js = patches(q);
        for (const int i : patches(h.nodes[static_cast<std::size_t>(receiver)]))
            for (const int j : js)
                ff.error[static_cast<std::size_t>(i) * un + static_cast<std::size_t>(j)] +=
                    error * ff.area[static_cast<std::size_t>(j)] / q.area;
    });
    ff.stats = h.leaf_stats;
    return ff;
}

std::size_t hierarchy_bytes(const Hierarchy& h) {
    // The links as held: a vector read from the cache reserves room for every link in both
    // kinds, and the room a kind leaves untouched is never resident.
    return h.nodes.capacity() * sizeof(HierarchyNode) + h.links.size() * sizeof(Link) +
           h.pair_links.size() * sizeof(PairLink) +
           (h.first_link.capacity() + h.first_pair_link.capacity()) * sizeof(std::int64_t) +
           h.leaf_of_patch.capacity() * sizeof(int);
}

FormFactorChecks check_hierarchy(const Hierarchy& h, double leaf_tolerance) {
    FormFactorChecks c;
    const std::vector<double> rows = h.row_sums();
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (const double e = std::abs(rows[i] - 1.0); c.closure_worst_patch < 0 || e > c.closure_max_error) {
            c.closure_max_error = e;
            c.closure_worst_patch = static_cast<int>(i);
        }
    std::vector<double> node_err(h.nodes.size(), 0.0);
    // Each link against its reverse, which is of the same kind (a pair proven or sampled to
    // exchange nothing has neither).
    const auto check = [&](const auto& links, const std::vector<std::int64_t>& first) {
        for (const auto& l : links) {
            const HierarchyNode& p = h.nodes[static_cast<std::size_t>(l.receiver)];
            const HierarchyNode& q = h.nodes[static_cast<std::size_t>(l.source)];
            node_err[static_cast<std::size_t>(l.receiver)] += l.error;
            c.min_entry = std::min(c.min_entry, l.f);
            c.max_error_estimate = std::max(c.max_error_estimate, l.error);
            const double target = p.leaf() && q.leaf() ? leaf_tolerance * std::min(p.area, q.area) / p.area
                                                       : h.options.tolerance;
            if (l.error > target) {
                ++c.entries_over_tolerance;
                if (l.error / target > c.worst_miss_ratio) {
                    c.worst_miss_ratio = l.error / target;
                    c.worst_miss_estimate = l.error;
                    c.worst_miss_i = p.leaf() ? p.patch : -1;
                    c.worst_miss_j = q.leaf() ? q.patch : -1;
                }
            }
            const auto b = links.begin() + first[static_cast<std::size_t>(l.source)];
            const auto e = links.begin() + first[static_cast<std::size_t>(l.source) + 1];
            const auto r =
                std::lower_bound(b, e, l.receiver, [](const auto& k, int v) { return k.source < v; });
            const bool reverse = r != e && r->source == l.receiver;
            const double g = p.area * l.f, g_rev = reverse ? q.area * r->f : 0.0;
            if (const double top = std::max(g, g_rev); top > 0.0) {
                c.reciprocity_max_error = std::max(c.reciprocity_max_error, std::abs(g - g_rev) / top);
                c.reciprocity_abs_error = std::max(c.reciprocity_abs_error, std::abs(g - g_rev) / p.area);
                const double est = p.area * l.error + (reverse ? q.area * r->error : 0.0);
                if (est > 0.0)
                    c.reciprocity_vs_estimate =
                        std::max(c.reciprocity_vs_estimate, std::abs(g - g_rev) / est);
            }
        }
    };
    check(h.links, h.first_link);
    check(h.pair_links, h.first_pair_link);
    const std::vector<double> row_err = h.to_patches(std::move(node_err));
    for (const double e : row_err) c.max_row_error_estimate = std::max(c.max_row_error_estimate, e);
    return c;
}

namespace {
template <class L>
std::vector<std::int64_t> index_of(const std::vector<L>& links, std::size_t nodes) {
    std::vector<std::int64_t> first(nodes + 1, 0);
    for (const L& l : links) ++first[static_cast<std::size_t>(l.receiver) + 1];
    for (std::size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
    return first;
}
}  // namespace

void index_links(Hierarchy* h) {
    h->first_link = index_of(h->links, h->nodes.size());
    h->first_pair_link = index_of(h->pair_links, h->nodes.size());
    h->stats.links = h->link_count();
}

}  // namespace radiosa
