#include "schedule/scheduler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "geometry/scene_geometry.h"

namespace radiosa {

const char* solve_action_name(SolveAction a) {
    switch (a) {
        case SolveAction::Factorised:
            return "factorised";
        case SolveAction::Substituted:
            return "substituted";
        case SolveAction::Iterated:
            return "iterated";
        case SolveAction::Combined:
            return "combined";
        case SolveAction::Reused:
            return "reused";
        case SolveAction::Ahead:
            return "ahead";
    }
    return "?";
}

const char* render_action_name(RenderAction a) { return a == RenderAction::Rendered ? "rendered" : "copied"; }

bool same_camera(const CameraDesc& a, const CameraDesc& b) {
    return a.eye == b.eye && a.look_at == b.look_at && a.up == b.up && a.fov_deg == b.fov_deg;
}

int Plan::renders() const {
    return static_cast<int>(std::count_if(
        frames.begin(), frames.end(), [](const FramePlan& f) { return f.render == RenderAction::Rendered; }));
}

bool Plan::is_identity(const std::vector<Similarity>& motion) {
    return std::all_of(motion.begin(), motion.end(), [](const Similarity& m) { return m.identity(); });
}

namespace {

// The emissions iterated directly for one reflectance set, one channel at a time: an orthonormal
// basis q of their span (Gram-Schmidt, each projection taken twice so that it stays orthogonal
// to rounding) and the triangle r with E_member_j = sum_{i <= j} r[j][i] q_i.
struct ChannelSpan {
    std::vector<int> members;               // solution indices
    std::vector<double> member_norm;        // |E_member|
    std::vector<std::vector<double>> q, r;  // r[j]: column j, j + 1 entries
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

// The coefficients y of e on the basis and what is left of e, resid = e - sum y_i q_i.
void project(const ChannelSpan& span, std::vector<double> e, std::vector<double>* y,
             std::vector<double>* resid) {
    y->assign(span.q.size(), 0.0);
    for (int pass = 0; pass < 2; ++pass)
        for (std::size_t i = 0; i < span.q.size(); ++i) {
            const double c = dot(span.q[i], e);
            (*y)[i] += c;
            for (std::size_t k = 0; k < e.size(); ++k) e[k] -= c * span.q[i][k];
        }
    *resid = std::move(e);
}

// The weights of the members that give y (back substitution in r), or nothing when they
// amplify the members' errors more than kMaxCombinationGain times |e|.
std::optional<std::vector<double>> weights(const ChannelSpan& span, const std::vector<double>& y,
                                           double norm) {
    const std::size_t k = y.size();
    std::vector<double> w(k, 0.0);
    for (std::size_t j = k; j-- > 0;) {
        double v = y[j];
        for (std::size_t i = j + 1; i < k; ++i) v -= span.r[i][j] * w[i];
        w[j] = v / span.r[j][j];
    }
    double gain = 0.0;
    for (std::size_t j = 0; j < k; ++j) gain += std::abs(w[j]) * span.member_norm[j];
    if (!(gain <= kMaxCombinationGain * norm)) return std::nullopt;
    return w;
}

std::vector<double> channel(const std::vector<Rgb>& E, int c) {
    std::vector<double> e(E.size());
    for (std::size_t i = 0; i < E.size(); ++i) e[i] = E[i][c];
    return e;
}

// Solution `sol`'s terms when its emission is a combination of the set's members in every
// channel; else empty, and it joins the members (in each channel where it adds a direction).
std::vector<Combination> combine_or_join(std::array<ChannelSpan, 3>& spans, const std::vector<Rgb>& E,
                                         int sol) {
    std::vector<Combination> terms;
    std::array<std::vector<double>, 3> resid;
    std::array<std::vector<double>, 3> ys;
    std::array<double, 3> norms{};
    bool combined = true;
    for (int c = 0; c < 3; ++c) {
        const std::vector<double> e = channel(E, c);
        norms[c] = std::sqrt(dot(e, e));
        project(spans[c], e, &ys[c], &resid[c]);
        if (norms[c] == 0.0) continue;  // a dark channel: no terms
        const bool in_span = std::sqrt(dot(resid[c], resid[c])) <= 1e-12 * norms[c];
        const auto w = in_span ? weights(spans[c], ys[c], norms[c]) : std::nullopt;
        if (!w) {
            combined = false;
            continue;
        }
        for (std::size_t j = 0; j < w->size(); ++j) {
            const int m = spans[c].members[j];
            auto t = std::find_if(terms.begin(), terms.end(),
                                  [&](const Combination& x) { return x.solution == m; });
            if (t == terms.end()) t = terms.insert(terms.end(), Combination{m, Rgb(0.0)});
            t->weight[c] = (*w)[j];
        }
    }
    if (combined && !terms.empty()) return terms;
    for (int c = 0; c < 3; ++c) {
        ChannelSpan& span = spans[c];
        const double left = std::sqrt(dot(resid[c], resid[c]));
        // Only a clear new direction joins: a nearly dependent one would make r ill-conditioned.
        if (!(left > 1e-6 * norms[c]) || static_cast<int>(span.members.size()) >= kMaxCombinationTerms)
            continue;
        for (double& v : resid[c]) v /= left;
        span.q.push_back(std::move(resid[c]));
        ys[c].push_back(left);
        span.r.push_back(std::move(ys[c]));
        span.members.push_back(sol);
        span.member_norm.push_back(norms[c]);
    }
    return {};
}

}  // namespace

int solved_ahead_limit(int patches) {
    constexpr double kBudget = 256.0 * 1024 * 1024, kPerPatch = 512.0;
    return std::clamp(1 + static_cast<int>(kBudget / (kPerPatch * std::max(patches, 1))), 1, kMaxSolvedAhead);
}

namespace {

// With `combine`: each reflectance set's Iterated solutions, in order of first use, in groups
// of up to `limit` solved by the first one's frame; the others' frames become Ahead.
void solve_ahead(Plan* plan, bool combine, int limit) {
    const int n = static_cast<int>(plan->solutions.size());
    plan->solved_with.resize(static_cast<std::size_t>(n));
    plan->solved_together.assign(static_cast<std::size_t>(n), {});
    std::vector<int> open(plan->reflectances.size(), -1);  // per set, the group still taking members
    for (int sol = 0; sol < n; ++sol) {
        const auto k = static_cast<std::size_t>(sol);
        plan->solved_with[k] = sol;
        if (!plan->combinations[k].empty()) continue;  // Combined: its terms are solved
        int& lead = open[static_cast<std::size_t>(plan->solution_set[k])];
        if (combine && lead >= 0 &&
            static_cast<int>(plan->solved_together[static_cast<std::size_t>(lead)].size()) < limit) {
            plan->solved_together[static_cast<std::size_t>(lead)].push_back(sol);
            plan->solved_with[k] = lead;
            continue;
        }
        lead = sol;
        plan->solved_together[k] = {sol};
    }
    for (FramePlan& fp : plan->frames)
        if (fp.solve == SolveAction::Iterated &&
            plan->solved_with[static_cast<std::size_t>(fp.solution)] != fp.solution)
            fp.solve = SolveAction::Ahead;
}

}  // namespace

Plan plan_sequence(const Sequence& seq, const Materials& base, const SceneGeometry& geometry, bool iterative,
                   bool combine) {
    Plan plan;
    std::vector<std::array<ChannelSpan, 3>> spans;  // per reflectance set, when combining
    for (int f = 0; f < seq.frames; ++f) {
        FramePlan fp;
        fp.frame = f;
        fp.time_s = seq.frame_time(f);
        fp.camera = seq.camera_at(fp.time_s);
        Materials m = seq.materials_at(base, geometry, fp.time_s);

        std::vector<Similarity> motion = seq.motion_at(geometry.surface_count(), fp.time_s);
        const auto gs = std::find(plan.geometries.begin(), plan.geometries.end(), motion);
        fp.geometry = static_cast<int>(gs - plan.geometries.begin());
        if (gs == plan.geometries.end()) {
            plan.geometries.push_back(std::move(motion));
            plan.last_frame_of_geometry.push_back(f);
        }
        plan.last_frame_of_geometry[static_cast<std::size_t>(fp.geometry)] = f;

        int rs = 0;
        while (rs < static_cast<int>(plan.reflectances.size()) &&
               !(plan.reflectance_geometry[rs] == fp.geometry && plan.reflectances[rs] == m.rho))
            ++rs;
        const bool new_rho = rs == static_cast<int>(plan.reflectances.size());
        fp.reflectance_set = rs;
        if (new_rho) {
            plan.reflectances.push_back(m.rho);
            plan.reflectance_geometry.push_back(fp.geometry);
        }

        int sol = 0;
        while (sol < static_cast<int>(plan.solutions.size()) &&
               !(plan.solution_set[sol] == rs && plan.solutions[sol].E == m.E))
            ++sol;
        fp.solution = sol;
        if (sol == static_cast<int>(plan.solutions.size())) {
            std::vector<Combination> terms;
            if (iterative && combine) {
                if (spans.size() <= static_cast<std::size_t>(rs))
                    spans.resize(static_cast<std::size_t>(rs) + 1);
                terms = combine_or_join(spans[static_cast<std::size_t>(rs)], m.E, sol);
            }
            plan.solutions.push_back(std::move(m));
            plan.solution_set.push_back(rs);
            fp.solve = !terms.empty() ? SolveAction::Combined
                       : iterative    ? SolveAction::Iterated
                       : new_rho      ? SolveAction::Factorised
                                      : SolveAction::Substituted;
            plan.combinations.push_back(std::move(terms));
        } else {
            fp.solve = SolveAction::Reused;
        }

        const bool same_as_previous = f > 0 && plan.frames.back().solution == fp.solution &&
                                      same_camera(plan.frames.back().camera, fp.camera);
        fp.render = same_as_previous ? RenderAction::Copied : RenderAction::Rendered;
        plan.frames.push_back(fp);
    }
    solve_ahead(&plan, iterative && combine, solved_ahead_limit(geometry.patch_count()));
    return plan;
}

}  // namespace radiosa
