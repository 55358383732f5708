#pragma once
// The geometry states of a sequence with moving surfaces (docs/sequences.md, "Moving
// surfaces"): each state's placed scene, geometry, form factors and sensor factors, obtained
// once, when its first frame needs it — the scene as read (state without motion), the disk
// cache, or an incremental update of the last state obtained (formfactor/incremental.h) — and
// released after its last frame.
#include <memory>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "app/form_factor_request.h"
#include "app/pipeline.h"
#include "formfactor/incremental.h"
#include "schedule/scheduler.h"

namespace radiosa {

struct GeometryState {
    const SceneGeometry* geometry = nullptr;
    const FormFactors* ff = nullptr;
    const std::vector<SensorFactors>* sensors = nullptr;
    // How its form factors were obtained, when not the scene file's own placement's: from a
    // cache file for this placement, or by an incremental update (what it recomputed).
    bool cached = false;
    std::optional<FormFactorUpdate> update;
    FormFactorChecks checks;
    double seconds = 0.0;  // obtaining it (placing, loading or updating, checks, sensors)

    // What a moved state owns (null / empty for the scene's own placement).
    std::unique_ptr<Scene> own_scene;
    std::unique_ptr<SceneGeometry> own_geometry;
    std::unique_ptr<FormFactors> own_ff;
    std::vector<SensorFactors> own_sensors;
};

class GeometryStates {
public:
    GeometryStates(const Prepared& base, const Plan& plan, const Sequence& sequence,
                   const FormFactorRequest& request, const WarningSink& warn);
    // State g, obtained now if it is not held; *obtained says whether it was.
    const GeometryState& enter(int g, bool* obtained);
    const GeometryState& state(int g) const { return *m_states[static_cast<std::size_t>(g)]; }
    // After the last frame of state g: its memory is released (kept while it is the latest, the
    // source of the next update).
    void release(int g);

private:
    std::unique_ptr<GeometryState> place(int g);
    void check_intersections(int g, const SceneGeometry& geometry);

    const Prepared& m_base;
    const Plan& m_plan;
    const Sequence& m_sequence;
    const FormFactorRequest& m_request;
    WarningSink m_warn;
    std::vector<std::unique_ptr<GeometryState>> m_states;
    std::vector<char> m_done;                // per state: its last frame has passed
    int m_last = -1;                         // the state obtained last
    std::set<std::pair<int, int>> m_warned;  // intersecting surface pairs already reported
};

}  // namespace radiosa
