#include "solve/link_solver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "util/channels.h"
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

// Each patch's area (its leaf node's).
std::vector<double> patch_areas(const Hierarchy& h) {
    std::vector<double> area;
    area.reserve(h.leaf_of_patch.size());
    for (const int leaf : h.leaf_of_patch) area.push_back(h.nodes[static_cast<std::size_t>(leaf)].area);
    return area;
}

}  // namespace

SolveDiagnostics diagnose_links(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B) {
    return diagnose_links(h, m, B, h.irradiance(B));
}

SolveDiagnostics diagnose_links(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B,
                                const std::vector<Rgb>& H) {
    return diagnose_irradiance(patch_areas(h), m, B, H);
}

namespace {

// What the links' estimates put into the interreflection of radiosities B: every link's estimate
// times the largest radiosity under its source, pushed to the patches, times rho there.
std::vector<Rgb> estimate_source(const Hierarchy& h, const std::vector<Rgb>& rho, const std::vector<Rgb>& B) {
    const std::vector<Rgb> top = pull_max(h, B);
    std::vector<Rgb> node_e(h.nodes.size(), Rgb(0.0));
    h.for_each_link([&](int receiver, int source, double error) {
        node_e[static_cast<std::size_t>(receiver)] += error * top[static_cast<std::size_t>(source)];
    });
    std::vector<Rgb> e = h.to_patches(std::move(node_e));
    for (std::size_t i = 0; i < e.size(); ++i) e[i] *= rho[i];
    return e;
}

// max d / max B per channel (0 for a dark channel).
Rgb relative_max(const std::vector<Rgb>& d, const std::vector<Rgb>& B) {
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

// An estimate needs no more digits than a millionth of itself.
LinkSolveOptions estimate_options(LinkSolveOptions o) {
    o.tolerance = std::max(o.tolerance, 1e-6);
    return o;
}

}  // namespace

Rgb link_error_estimate(const Hierarchy& h, const Materials& m, const std::vector<Rgb>& B,
                        const LinkSolveOptions& options) {
    return relative_max(solve_links(h, m.rho, estimate_source(h, m.rho, B), estimate_options(options)).B, B);
}

std::vector<Rgb> link_error_estimates(const Hierarchy& h, const std::vector<Rgb>& rho,
                                      const std::vector<const std::vector<Rgb>*>& B,
                                      const LinkSolveOptions& options) {
    std::vector<std::vector<Rgb>> sources;
    for (const std::vector<Rgb>* b : B) sources.push_back(estimate_source(h, rho, *b));
    const std::vector<LinkSolution> d = solve_links_together(h, rho, sources, estimate_options(options));
    std::vector<Rgb> out;
    for (std::size_t j = 0; j < B.size(); ++j) out.push_back(relative_max(d[j].B, *B[j]));
    return out;
}

namespace {

// Chebyshev acceleration of the sweeps (Golub & Varga 1961; Varga, Matrix Iterative Analysis,
// ch. 5): x_{k+1} = x_{k-1} + w_{k+1} (J(x_k) - x_{k-1}), J the Jacobi sweep, with w_1 = 1,
// w_2 = 1 / (1 - l^2 / 2) and w_{k+1} = 1 / (1 - l^2 w_k / 4) for eigenvalues of rho F in
// [-l, l]. With reciprocal form factors (A_i F_ij = A_j F_ji) rho F is self-adjoint in the inner
// product weighted by A / rho, so its eigenvalues are real; the largest, l*, is Jacobi's rate.
// With l = l* the error shrinks per sweep by l / (1 + sqrt(1 - l^2)) instead of l (0.36 instead
// of 0.64 at l = 0.64, 0.72 instead of 0.95 at l = 0.95). An l above l* costs little (0.39 for
// l = 0.68 over 0.64), one below it much, so l is the Rayleigh quotient of Jacobi's changes
// (d_k = K d_{k-1}: <d_{k-1}, W d_k> / <d_{k-1}, W d_{k-1}>, which tends to l* from below, its
// error squared at every sweep) plus a tenth of its distance to 1. Should the accelerated
// changes ever grow a thousandfold (links far from reciprocal: complex eigenvalues), the plain
// sweeps take over again.
template <class T>
class Chebyshev {
public:
    Chebyshev(const Hierarchy& h, const std::vector<T>& rho) : m_weight(rho.size(), T(0.0)) {
        const std::vector<double> area = patch_areas(h);
        for (std::size_t i = 0; i < rho.size(); ++i)
            for (int c = 0; c < kC; ++c)
                if (rho[i][c] > 0.0) m_weight[i][c] = area[i] / rho[i][c];
    }
    bool on() const { return m_on; }
    const T& weight() const { return m_w; }

    // After sweep `sweep`, whose change J(x) - x per patch is `d` (per channel at most `largest`):
    // reads the rate while plain, then switches on.
    void observe(int sweep, const std::vector<T>& d, const T& largest) {
        if (m_on) return watch(largest);
        if (m_off) return;
        if (sweep >= 2) {
            T num(0.0), den(0.0);
            for (std::size_t i = 0; i < d.size(); ++i) {
                num += m_weight[i] * m_d[i] * d[i];
                den += m_weight[i] * m_d[i] * m_d[i];
            }
            const T was = m_quotient;
            for (int c = 0; c < kC; ++c)
                m_quotient[c] = den[c] > 0.0 ? std::clamp(num[c] / den[c], 0.0, 1.0) : 0.0;
            bool settled = true;
            for (int c = 0; c < kC; ++c)
                settled = settled && std::abs(m_quotient[c] - was[c]) <= 0.01 * m_quotient[c];
            if (sweep >= kLast || (sweep >= kFirst && settled)) {
                for (int c = 0; c < kC; ++c)
                    m_l[c] = std::min(m_quotient[c] + 0.1 * (1.0 - m_quotient[c]), kMax);
                m_on = true;
                m_least = largest;
                // This sweep's J(x_k) with x_k = J(x_{k-1}) makes the second Chebyshev step.
                for (int c = 0; c < kC; ++c) m_w[c] = 1.0 / (1.0 - 0.5 * m_l[c] * m_l[c]);
                return;
            }
        }
        m_d = d;
    }
    // The weight for the sweep after this one's.
    void advance() {
        for (int c = 0; c < kC; ++c) m_w[c] = 1.0 / (1.0 - 0.25 * m_l[c] * m_l[c] * m_w[c]);
    }

private:
    static constexpr int kC = T::length();  // channels (3 per right-hand side)
    static constexpr int kFirst = 3;        // plain sweeps before the rate may be taken
    static constexpr int kLast = 12;        // taken by then, settled or not
    static constexpr double kMax = 0.999;   // the largest l used

    void watch(const T& largest) {
        for (int c = 0; c < kC; ++c) {
            m_least[c] = std::min(m_least[c], largest[c]);
            if (largest[c] > 1e3 * m_least[c]) {
                m_on = false;
                m_off = true;
                m_w = T(1.0);
            }
        }
    }

    std::vector<T> m_weight;  // A / rho per patch and channel (0 for black)
    std::vector<T> m_d;       // the last plain sweep's change
    T m_quotient{0.0}, m_l{0.0}, m_w{1.0}, m_least{0.0};
    bool m_on = false, m_off = false;
};

template <class T>
T elementwise_max(T a, const T& b) {
    for (int c = 0; c < T::length(); ++c) a[c] = std::max(a[c], b[c]);
    return a;
}
template <class T>
T elementwise_abs(T a) {
    for (int c = 0; c < T::length(); ++c) a[c] = std::abs(a[c]);
    return a;
}

// The sweeps on every channel of T at once (Rgb: one emission; Channels<3 K>: K of them), each
// channel's iteration exactly its own: only the stop is shared (the worst channel's change).
template <class T>
struct Swept {
    std::vector<T> B;
    int sweeps = 0;
    double change = 0.0;  // worst channel
    T relative{0.0};      // per channel, the last change / max B (0 for a dark channel)
};

template <class T>
Swept<T> sweep_links(const Hierarchy& h, const std::vector<T>& rho, const std::vector<T>& E,
                     const LinkSolveOptions& options, std::vector<T> start) {
    Swept<T> s;
    s.B = std::move(start);
    const std::size_t n = E.size();
    // A dark channel's answer is 0. From a warm start of lit radiosities it would only decay,
    // its change measured against its own largest value, until that overshot below 0 and the
    // channel passed for settled, negative values and all.
    T lit(0.0);
    for (const T& e : E) lit = elementwise_max(lit, elementwise_abs(e));
    for (T& b : s.B)
        for (int c = 0; c < T::length(); ++c)
            if (lit[c] == 0.0) b[c] = 0.0;
    std::vector<T> older = s.B, next(n), d(n);  // x_{k-1}, J(x_k) and J(x_k) - x_k
    std::vector<double> changes;                // s.change per sweep
    Chebyshev<T> cheb(h, rho);
    for (s.sweeps = 1; s.sweeps <= options.max_sweeps; ++s.sweeps) {
        const std::vector<T> patch_h = h.irradiance(s.B);
        T change(0.0), top(0.0);
        for (std::size_t i = 0; i < n; ++i) {
            next[i] = E[i] + rho[i] * patch_h[i];
            d[i] = next[i] - s.B[i];
            change = elementwise_max(change, elementwise_abs(d[i]));
            top = elementwise_max(top, next[i]);
        }
        s.change = 0.0;
        for (int c = 0; c < T::length(); ++c) {
            s.relative[c] = top[c] > 0.0 ? change[c] / top[c] : 0.0;
            s.change = std::max(s.change, s.relative[c]);
        }
        // The change is J(x) - x, the residual: below the tolerance, J(x) is the answer.
        if (s.change <= options.tolerance) {
            s.B = std::move(next);
            return s;
        }
        changes.push_back(s.change);
        // The change shrinks by a steady rate per sweep (plain: the spectral radius of rho F):
        // past a few dozen sweeps, a rate that would need more than max_sweeps is known already.
        // Accelerated changes are not monotone, so the rate is taken over twenty sweeps.
        if (s.sweeps >= 50 && changes[changes.size() - 21] > 0.0) {
            const double rate = std::pow(s.change / changes[changes.size() - 21], 0.05);
            if (rate >= 1.0 ||
                s.sweeps + std::log(options.tolerance / s.change) / std::log(rate) > options.max_sweeps)
                break;
        }
        const bool was_on = cheb.on();
        if (options.accelerate) cheb.observe(s.sweeps, d, change);
        if (cheb.on()) {
            const T w = cheb.weight();
            for (std::size_t i = 0; i < n; ++i) {
                const T x = older[i] + w * (next[i] - older[i]);
                older[i] = s.B[i];
                s.B[i] = x;
            }
            cheb.advance();
        } else {
            if (was_on) older = s.B;  // the plain sweeps take over from here
            std::swap(older, s.B);
            std::swap(s.B, next);
        }
    }
    throw Error("the radiosity over the hierarchy's links does not settle within " +
                std::to_string(options.max_sweeps) + " sweeps (change " + std::to_string(s.change) +
                " of the largest radiosity after " + std::to_string(s.sweeps) +
                "): reflectances too close to 1 for this scene; lower them");
}

// Vectors v[0..K) of Rgb per patch side by side in one vector of Channels<C> (K <= C / 3; any
// channel left over zero), and back.
template <int C>
std::vector<Channels<C>> side_by_side(const std::vector<const std::vector<Rgb>*>& v, std::size_t n) {
    std::vector<Channels<C>> out(n, Channels<C>(0.0));
    for (std::size_t j = 0; j < v.size(); ++j)
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) out[i][static_cast<int>(3 * j) + c] = (*v[j])[i][c];
    return out;
}
template <int C>
std::vector<Rgb> column(const std::vector<Channels<C>>& v, std::size_t j) {
    std::vector<Rgb> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
        for (int c = 0; c < 3; ++c) out[i][c] = v[i][static_cast<int>(3 * j) + c];
    return out;
}

template <int C>
std::vector<LinkSolution> sweep_together(const Hierarchy& h, const std::vector<Rgb>& rho,
                                         const std::vector<std::vector<Rgb>>& E,
                                         const std::vector<const std::vector<Rgb>*>& starts,
                                         const LinkSolveOptions& options) {
    const std::size_t n = rho.size(), k = E.size();
    std::vector<const std::vector<Rgb>*> e, x0, r(k, &rho);
    for (std::size_t j = 0; j < k; ++j) {
        e.push_back(&E[j]);
        x0.push_back(j < starts.size() && starts[j] ? starts[j] : &E[j]);
    }
    Swept<Channels<C>> s =
        sweep_links(h, side_by_side<C>(r, n), side_by_side<C>(e, n), options, side_by_side<C>(x0, n));
    std::vector<LinkSolution> out(k);
    for (std::size_t j = 0; j < k; ++j) {
        out[j].sweeps = s.sweeps;
        out[j].B = column(s.B, j);
        for (int c = 0; c < 3; ++c)
            out[j].change = std::max(out[j].change, s.relative[static_cast<int>(3 * j) + c]);
    }
    return out;
}

template <int C>
std::vector<std::vector<Rgb>> gather_together(const Hierarchy& h,
                                              const std::vector<const std::vector<Rgb>*>& B) {
    const std::vector<Channels<C>> H = h.irradiance(side_by_side<C>(B, B[0]->size()));
    std::vector<std::vector<Rgb>> out;
    for (std::size_t j = 0; j < B.size(); ++j) out.push_back(column(H, j));
    return out;
}

}  // namespace

LinkSolution solve_links(const Hierarchy& h, const std::vector<Rgb>& rho, const std::vector<Rgb>& E,
                         const LinkSolveOptions& options, const std::vector<Rgb>* start) {
    Swept<Rgb> s = sweep_links(h, rho, E, options, start ? *start : E);
    return {std::move(s.B), s.sweeps, s.change};
}

namespace {

// f.template operator()<3 K>() for K = count in [2, kMaxSolvedTogether]: the emissions side by
// side with no column to spare (the sweeps' arithmetic grows with the columns).
template <class F>
auto with_columns(std::size_t count, F&& f) {
    static_assert(kMaxSolvedTogether == 8, "one case per count");
    switch (count) {
        case 2:
            return f.template operator()<6>();
        case 3:
            return f.template operator()<9>();
        case 4:
            return f.template operator()<12>();
        case 5:
            return f.template operator()<15>();
        case 6:
            return f.template operator()<18>();
        case 7:
            return f.template operator()<21>();
        case 8:
            return f.template operator()<24>();
        default:
            throw std::invalid_argument("more than kMaxSolvedTogether right-hand sides at once");
    }
}

}  // namespace

std::vector<LinkSolution> solve_links_together(const Hierarchy& h, const std::vector<Rgb>& rho,
                                               const std::vector<std::vector<Rgb>>& E,
                                               const LinkSolveOptions& options,
                                               const std::vector<const std::vector<Rgb>*>& starts) {
    if (E.empty()) return {};
    if (E.size() == 1) return {solve_links(h, rho, E[0], options, starts.empty() ? nullptr : starts[0])};
    return with_columns(E.size(), [&]<int C>() { return sweep_together<C>(h, rho, E, starts, options); });
}

std::vector<std::vector<Rgb>> irradiance_together(const Hierarchy& h,
                                                  const std::vector<const std::vector<Rgb>*>& B) {
    if (B.empty()) return {};
    if (B.size() == 1) return {h.irradiance(*B[0])};
    return with_columns(B.size(), [&]<int C>() { return gather_together<C>(h, B); });
}

}  // namespace radiosa
