#pragma once
// Globally adaptive cubature over a parameter rectangle, for the outer integral of the
// error-controlled form factors (formfactor/form_factor.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "geometry/scene_geometry.h"
#include "surfaces/surface.h"
#include "util/gauss_legendre.h"

namespace radiosa {

struct Rect {
    double s0, s1, t0, t1;
    // Halves along s (dir 0) or t (dir 1).
    std::array<Rect, 2> halves(int dir) const { return cut(dir, std::numeric_limits<double>::quiet_NaN()); }
    // The two parts either side of s = at (dir 0) or t = at (dir 1); the midpoint when `at` is NaN.
    std::array<Rect, 2> cut(int dir, double at) const {
        if (dir == 0) {
            const double m = std::isnan(at) ? 0.5 * (s0 + s1) : at;
            return {Rect{s0, m, t0, t1}, Rect{m, s1, t0, t1}};
        }
        const double m = std::isnan(at) ? 0.5 * (t0 + t1) : at;
        return {Rect{s0, s1, t0, m}, Rect{s0, s1, m, t1}};
    }
};

// A split a geometric rule demands: along s (dir 0) or t (dir 1), at `at` (NaN: the midpoint);
// dir -1 demands none. Rules that only ever split at midpoints may return the direction alone.
// With a `bound` (not NaN) nothing is demanded: geometry proves the integral over the region in
// [0, bound] (a region that may see a sliver its nodes miss, and what that sliver can be worth
// at most); the region then splits along `dir` only if its error is among the largest.
struct Cut {
    int dir = -1;
    double at = std::numeric_limits<double>::quiet_NaN();
    double bound = std::numeric_limits<double>::quiet_NaN();
};
inline Cut as_cut(int dir) { return Cut{dir}; }
inline Cut as_cut(Cut c) { return c; }

// A quadrature point of a patch: its position and its normal scaled by the weight and by
// the Jacobian of the map from [-1,1]^2 to the patch's parameter rectangle, so that
// sum over points of f(x) |nw| approximates the integral of f over the patch area.
struct QuadPoint {
    Vec3 x;
    Vec3 nw;
};

inline std::vector<QuadPoint> quadrature_points(const Surface& surf, const Patch& p, const GaussRule& rule) {
    const int n = static_cast<int>(rule.x.size());
    const double hs = 0.5 * (p.s1 - p.s0), ht = 0.5 * (p.t1 - p.t0);
    std::vector<QuadPoint> pts;
    pts.reserve(static_cast<size_t>(n) * n);
    for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) {
            const double s = p.s0 + hs * (rule.x[a] + 1.0);
            const double t = p.t0 + ht * (rule.x[b] + 1.0);
            QuadPoint& q = pts.emplace_back();
            surf.point_and_normal(s, t, &q.x, &q.nw);
            q.nw *= rule.w[a] * rule.w[b] * hs * ht;
        }
    return pts;
}

struct Estimate {
    double value = 0.0;
    double error = 0.0;
    int regions = 0;
    bool capped = false;
};

// Globally adaptive cubature of g(s, t) over a parameter rectangle with anisotropic splits.
// Each region carries its p x p Gauss value (coarse) and the sums over its two halves along s
// and along t; |halves - coarse| summed over both directions estimates the error (it bounds
// the coarse value's error and the disagreement of the two refinements), and the direction
// with the larger change is where the integrand varies most: the region is
// split there, so a feature along a line (an edge the other patch touches or nearly touches)
// is followed by thin strips, not by squares. `geometric(r, fine)` may demand a split direction
// (0 or 1) regardless of the estimate, when the region is large compared to its distance from a
// near-singularity that no Gauss node of it would see, or when geometry proves a feature inside
// it that its nodes (whose sum `fine()` gives, computed only if asked for) all missed; -1
// otherwise. Regions are split until no split is demanded and the estimates sum to at most
// `tol`, or `max_regions` is reached.
// Nested-rule estimates can be fooled where the integrand is only once differentiable (a
// shadow's edge sweeping across a patch, a hair-thin gap); measured on the configurations of
// `radiosa accuracy`, true errors reached 3x the raw estimate, so estimates are scaled by 4.
// Worse, every nested rule splits at the same midlines, so a kink lying near one is missed by
// all of them alike. `suspect(r, fine)` says whether geometry puts such an event (a visibility
// or horizon change) inside the region, and how to count it: kCheckRegion, the estimate also
// compares the value with a 3 x 3 split, whose nodes lie elsewhere; a fraction f > 0 of the
// region's value that such a kink can cost at most, f |fine| is added to the estimate, and the
// 3 x 3 check replaces it only if the region comes to have the largest estimate (so a loose
// tolerance pays for no checks, a tight one for no splits a check would have spared); 0, no
// event.
constexpr double kSafety = 4.0;
inline constexpr double kCheckRegion = std::numeric_limits<double>::infinity();
// Regions wider than half the root along s (then t) are halved there: the first two levels of
// splitting, for integrands whose kinks an estimate over the whole root can miss.
inline Cut quarter_of(const Rect& root, const Rect& r) {
    if (r.s1 - r.s0 > 0.5 * (root.s1 - root.s0) * (1 + 1e-12)) return Cut{0};
    if (r.t1 - r.t0 > 0.5 * (root.t1 - root.t0) * (1 + 1e-12)) return Cut{1};
    return Cut{};
}

struct NoSuspects {
    double operator()(const Rect&, double) const { return 0.0; }
};

// The tensor Gauss rule over a region.
template <class G>
double tensor_gauss(const G& g, const Rect& r, const GaussRule& rule) {
    const double hs = 0.5 * (r.s1 - r.s0), ht = 0.5 * (r.t1 - r.t0);
    double sum = 0.0;
    for (std::size_t b = 0; b < rule.x.size(); ++b)
        for (std::size_t a = 0; a < rule.x.size(); ++a)
            sum += rule.w[a] * rule.w[b] * g(r.s0 + hs * (rule.x[a] + 1.0), r.t0 + ht * (rule.x[b] + 1.0));
    return sum * hs * ht;
}

// The rule on each of the region's 3 x 3 thirds: nodes away from those of its halves.
template <class G>
double gauss_thirds(const G& g, const Rect& r, const GaussRule& rule) {
    double sum = 0.0;
    const double ds = (r.s1 - r.s0) / 3.0, dt = (r.t1 - r.t0) / 3.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            sum += tensor_gauss(
                g, Rect{r.s0 + a * ds, r.s0 + (a + 1) * ds, r.t0 + b * dt, r.t0 + (b + 1) * dt}, rule);
    return sum;
}

namespace detail {

// A region of adaptive_rect: its p x p value split along `dir` and what its estimate holds.
struct Region {
    Rect r;
    std::array<double, 2> half;  // the two parts along `dir` (cut at `at`)
    int dir;
    double at;
    bool forced;
    double coarse;  // its p x p value; NaN until needed (a forced root's)
    double fine, err;
    double kink;  // the part of err that is a kink's largest share, not yet measured
    double key() const { return forced ? std::numeric_limits<double>::infinity() : err; }
};

// A value computed when first asked for: the sum over a region's halves along s, which a
// geometric rule may need (Geo's `fine`) and a rule that demands a cut from geometry alone
// never pays for.
template <class F>
class Lazy {
public:
    explicit Lazy(const F& f) : m_f(f) {}
    double operator()() const {
        if (!m_value) m_value = m_f();
        return *m_value;
    }

private:
    const F& m_f;
    mutable std::optional<double> m_value;
};

// How adaptive_rect makes its regions, and checks the ones geometry puts an event in.
template <class G, class Geo, class Sus>
class RegionRules {
public:
    RegionRules(const G& g, const GaussRule& rule, const Geo& geometric, const Sus& suspect)
        : m_g(g), m_rule(rule), m_geometric(geometric), m_suspect(suspect) {}

    double gauss(const Rect& r) const { return tensor_gauss(m_g, r, m_rule); }

    // The 3 x 3 check: the kink measured instead of counted at its largest share.
    void measure(Region& reg) const {
        reg.err =
            std::max(reg.err - reg.kink, kSafety * std::abs(gauss_thirds(m_g, reg.r, m_rule) - reg.fine));
        reg.kink = 0.0;
    }

    // A region geometry puts an event in: checked now, or its kink counted at its largest share
    // until the refinement would split the region for it (then it is checked instead).
    void check(Region& reg) const {
        const double kink = m_suspect(reg.r, reg.fine);
        if (kink == kCheckRegion) {
            measure(reg);
        } else if (kink > 0.0) {
            reg.kink = kink * std::abs(reg.fine);
            reg.err += reg.kink;
        }
    }

    // A region from its coarse value (known from its parent's split; NaN for the root, whose
    // value a forced cut does not need).
    Region make(const Rect& r, double coarse) const {
        Region reg{r, {}, 0, std::numeric_limits<double>::quiet_NaN(), false, coarse, 0.0, 0.0, 0.0};
        std::array<std::optional<std::array<double, 2>>, 2> h;
        auto halves = [&](int d) -> const std::array<double, 2>& {
            if (!h[d]) h[d] = halves_of(r, d);
            return *h[d];
        };
        auto s_halves = [&] { return halves(0)[0] + halves(0)[1]; };
        const Cut forced = as_cut(m_geometric(r, Lazy(s_halves)));
        const bool bounded = !std::isnan(forced.bound);
        reg.forced = forced.dir >= 0 && !bounded;
        if (reg.forced) {
            // Split whatever its estimate: only the parts it splits into are needed now, and its
            // estimate waits until it is left whole (at the cap, complete()), which gives the
            // same values and estimates for a third (a cut at `at`) or half of the work.
            reg.dir = forced.dir;
            reg.at = forced.at;
            if (std::isnan(forced.at)) {
                reg.half = halves(reg.dir);
            } else {  // a cut along a known feature (an event line): the parts either side of it
                const auto parts = r.cut(reg.dir, reg.at);
                reg.half = {gauss(parts[0]), gauss(parts[1])};
            }
            reg.fine = reg.half[0] + reg.half[1];
            return reg;
        }
        const std::array<double, 2> e = differences(reg, halves);
        reg.dir = forced.dir >= 0 ? forced.dir : (e[1] > e[0] ? 1 : 0);
        reg.half = halves(reg.dir);
        reg.fine = reg.half[0] + reg.half[1];
        estimate(reg, e);
        // A region with a proven bound needs no check: its value lies in [0, bound], so
        // |value - fine| <= max(bound, |fine|).
        if (bounded)
            reg.err = std::max({reg.err, forced.bound, std::abs(reg.fine)});
        else
            check(reg);
        return reg;
    }

    // A forced region left whole at the cap: its estimate and check, as make() gives them to a
    // region it does not force.
    void complete(Region& reg) const {
        estimate(reg, differences(reg, [&](int d) { return halves_of(reg.r, d); }));
        check(reg);
    }

private:
    // The rule on the region's two halves along s (d = 0) or t (d = 1).
    std::array<double, 2> halves_of(const Rect& r, int d) const {
        const auto hv = r.halves(d);
        return {gauss(hv[0]), gauss(hv[1])};
    }

    // How far the halves along s and along t are from the region's coarse value (computed here
    // first when not yet known: a forced root's).
    template <class Halves>
    std::array<double, 2> differences(Region& reg, Halves&& halves) const {
        if (std::isnan(reg.coarse)) reg.coarse = gauss(reg.r);
        std::array<double, 2> e;
        for (int d = 0; d < 2; ++d) {
            const std::array<double, 2> h = halves(d);
            e[d] = std::abs(h[0] + h[1] - reg.coarse);
        }
        return e;
    }

    // Never claim more than round-off allows: rules that happen to agree exactly still carry the
    // rounding of their sums.
    static void estimate(Region& reg, const std::array<double, 2>& e) {
        reg.err = kSafety * (e[0] + e[1]) + 64 * std::numeric_limits<double>::epsilon() * std::abs(reg.fine);
    }

    const G& m_g;
    const GaussRule& m_rule;
    const Geo& m_geometric;
    const Sus& m_suspect;
};

}  // namespace detail

// `leaves`, if given, receives the final regions (to integrate a companion quantity over them).
template <class G, class Geo, class Sus = NoSuspects>
Estimate adaptive_rect(const G& g, const Rect& root, double tol, int max_regions, const GaussRule& rule,
                       const Geo& geometric, const Sus& suspect = {}, std::vector<Rect>* leaves = nullptr) {
    using detail::Region;
    const detail::RegionRules<G, Geo, Sus> rules(g, rule, geometric, suspect);
    auto lower = [](const Region& a, const Region& b) { return a.key() < b.key(); };
    std::vector<Region> heap{rules.make(root, std::numeric_limits<double>::quiet_NaN())};
    double err = heap[0].err, value = heap[0].fine;
    // The value when half the regions had been spent: if the cap stops the refinement, how much
    // the value still moved over the second half bounds the error from below, where the
    // regions' own estimates (which assume convergence) may not.
    std::optional<double> value_at_half;
    while ((err > tol || heap.front().forced) && static_cast<int>(heap.size()) < max_regions) {
        if (!value_at_half && 2 * static_cast<int>(heap.size()) >= max_regions) value_at_half = value;
        std::pop_heap(heap.begin(), heap.end(), lower);
        Region top = heap.back();
        heap.pop_back();
        if (top.kink > 0.0) {
            // Largest only by its counted kink: measure it before splitting for it.
            err -= top.err;
            rules.measure(top);
            err += top.err;
            heap.push_back(top);
            std::push_heap(heap.begin(), heap.end(), lower);
            continue;
        }
        const auto hv = top.r.cut(top.dir, top.at);
        err -= top.err;
        value -= top.fine;
        for (int k = 0; k < 2; ++k) {
            heap.push_back(rules.make(hv[k], top.half[k]));
            err += heap.back().err;
            value += heap.back().fine;
            std::push_heap(heap.begin(), heap.end(), lower);
        }
    }
    for (Region& r : heap)
        if (r.forced) rules.complete(r);
    Estimate e;
    for (const Region& r : heap) {
        e.value += r.fine;
        e.error += r.err;
        if (leaves) leaves->push_back(r.r);
    }
    e.regions = static_cast<int>(heap.size());
    e.capped = e.error > tol || heap.front().forced;
    if (e.capped && value_at_half) e.error = std::max(e.error, kSafety * std::abs(e.value - *value_at_half));
    return e;
}

}  // namespace radiosa
