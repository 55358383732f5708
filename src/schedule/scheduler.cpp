#include "schedule/scheduler.h"

#include <algorithm>

namespace radiosa {

const char* solve_action_name(SolveAction a) {
    switch (a) {
        case SolveAction::Factorised:
            return "factorised";
        case SolveAction::Substituted:
            return "substituted";
        case SolveAction::Iterated:
            return "iterated";
        case SolveAction::Reused:
            return "reused";
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

Plan plan_sequence(const Sequence& seq, const Materials& base, const SceneGeometry& geometry,
                   bool iterative) {
    Plan plan;
    for (int f = 0; f < seq.frames; ++f) {
        FramePlan fp;
        fp.frame = f;
        fp.time_s = seq.frame_time(f);
        fp.camera = seq.camera_at(fp.time_s);
        Materials m = seq.materials_at(base, geometry, fp.time_s);

        auto rs = std::find(plan.reflectances.begin(), plan.reflectances.end(), m.rho);
        const bool new_rho = rs == plan.reflectances.end();
        fp.reflectance_set = static_cast<int>(rs - plan.reflectances.begin());
        if (new_rho) plan.reflectances.push_back(m.rho);

        auto sol = std::find_if(plan.solutions.begin(), plan.solutions.end(),
                                [&](const Materials& s) { return s.rho == m.rho && s.E == m.E; });
        fp.solution = static_cast<int>(sol - plan.solutions.begin());
        if (sol == plan.solutions.end()) {
            plan.solutions.push_back(std::move(m));
            fp.solve = iterative ? SolveAction::Iterated
                       : new_rho ? SolveAction::Factorised
                                 : SolveAction::Substituted;
        } else {
            fp.solve = SolveAction::Reused;
        }

        const bool same_as_previous = f > 0 && plan.frames.back().solution == fp.solution &&
                                      same_camera(plan.frames.back().camera, fp.camera);
        fp.render = same_as_previous ? RenderAction::Copied : RenderAction::Rendered;
        plan.frames.push_back(fp);
    }
    return plan;
}

}  // namespace radiosa
