#include "schedule/scheduler.h"

#include <algorithm>

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

bool Plan::is_identity(const std::vector<Similarity>& motion) {
    return std::all_of(motion.begin(), motion.end(), [](const Similarity& m) { return m.identity(); });
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
            plan.solutions.push_back(std::move(m));
            plan.solution_set.push_back(rs);
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
