#include "app/geometry_states.h"

#include <fmt/format.h>

#include <algorithm>

#include "geometry/intersections.h"
#include "scene/scene.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

GeometryStates::GeometryStates(const Prepared& base, const Plan& plan, const Sequence& sequence,
                               const FormFactorRequest& request, const WarningSink& warn)
    : m_base(base),
      m_plan(plan),
      m_sequence(sequence),
      m_request(request),
      m_warn(warn),
      m_states(plan.geometries.size()),
      m_done(plan.geometries.size(), 0) {}

const GeometryState& GeometryStates::enter(int g, bool* obtained) {
    auto& slot = m_states[static_cast<std::size_t>(g)];
    *obtained = !slot;
    if (!slot) {
        slot = place(g);
        const int previous = m_last;
        m_last = g;
        if (previous >= 0 && m_done[static_cast<std::size_t>(previous)]) release(previous);
    }
    return *slot;
}

void GeometryStates::release(int g) {
    m_done[static_cast<std::size_t>(g)] = 1;
    if (g != m_last) m_states[static_cast<std::size_t>(g)].reset();
}

// The surfaces of state g, the cache or an update from the last state, then checks and sensors.
std::unique_ptr<GeometryState> GeometryStates::place(int g) {
    const Stopwatch clock;
    auto st = std::make_unique<GeometryState>();
    const std::vector<Similarity>& motion = m_plan.geometries[static_cast<std::size_t>(g)];
    if (Plan::is_identity(motion)) {
        st->geometry = &m_base.geometry;
        st->ff = &m_base.ff;
        st->sensors = &m_base.sensors;
        st->checks = m_base.checks;
        return st;
    }
    st->own_scene = std::make_unique<Scene>(m_base.scene);
    for (std::size_t k = 0; k < motion.size(); ++k)
        st->own_scene->surfaces[k].shape = moved_shape(m_base.scene.surfaces[k], motion[k]);
    st->own_geometry = std::make_unique<SceneGeometry>(*st->own_scene);
    st->geometry = st->own_geometry.get();
    check_intersections(g, *st->geometry);

    CacheOutcome outcome;
    if (auto cached = find_cached_form_factors(*st->own_scene, *st->geometry, m_base.options, m_request.cache,
                                               &outcome)) {
        st->own_ff = std::make_unique<FormFactors>(std::move(*cached));
        st->cached = true;
    } else {
        // From the state obtained last: the previous frame's, nearest in time.
        const SceneGeometry* from_geometry = &m_base.geometry;
        const FormFactors* from_ff = &m_base.ff;
        GeometryState* last = m_last >= 0 ? m_states[static_cast<std::size_t>(m_last)].get() : nullptr;
        if (last) {
            from_geometry = last->geometry;
            from_ff = last->ff;
        }
        FormFactorUpdate u;
        // A moved state past its last frame is released once this one is obtained: its matrix
        // is updated in place instead of copied (N^2 entries: 0.8 s at 5,000 patches).
        if (last && last->own_ff && m_done[static_cast<std::size_t>(m_last)] != 0) {
            st->own_ff = std::make_unique<FormFactors>(update_form_factors(
                *from_geometry, std::move(*last->own_ff), *st->geometry, m_base.options, &u));
            last->ff = nullptr;
        } else {
            st->own_ff = std::make_unique<FormFactors>(
                update_form_factors(*from_geometry, *from_ff, *st->geometry, m_base.options, &u));
        }
        st->update = std::move(u);
    }
    st->ff = st->own_ff.get();
    st->checks = check_form_factors(*st->ff);
    const double sensor_tol = m_base.options.method == FormFactorMethod::Adaptive
                                  ? m_base.options.tolerance
                                  : kDefaultFormFactorTolerance;
    for (const SensorDesc& d : m_base.scene.sensors)
        st->own_sensors.push_back(
            sensor_factors(*st->geometry, d.position, d.normal, sensor_tol, m_base.options.visibility));
    st->sensors = &st->own_sensors;
    st->seconds = clock.seconds();
    return st;
}

// Surfaces a motion makes intersect (at a frame's time; between frames nothing is checked):
// an error with --strict, else one warning per pair. Pairs that already intersect in the scene
// file were reported when it was read.
void GeometryStates::check_intersections(int g, const SceneGeometry& geometry) {
    const std::vector<Similarity>& motion = m_plan.geometries[static_cast<std::size_t>(g)];
    for (const SurfaceIntersection& x : find_intersections(geometry)) {
        const bool moved = !motion[static_cast<std::size_t>(x.a)].identity() ||
                           !motion[static_cast<std::size_t>(x.b)].identity();
        const bool known =
            std::any_of(m_base.intersections.begin(), m_base.intersections.end(),
                        [&](const SurfaceIntersection& y) { return y.a == x.a && y.b == x.b; });
        if (!moved || known || !m_warned.insert({x.a, x.b}).second) continue;
        const int mover = motion[static_cast<std::size_t>(x.a)].identity() ? x.b : x.a;
        FileLoc loc{m_sequence.file, 0, 0};
        for (const SequenceEvent& ev : m_sequence.events)
            if (ev.property == EventProperty::Motion && ev.surface == mover) {
                loc = ev.loc;
                break;
            }
        double t = 0.0;
        for (const FramePlan& f : m_plan.frames)
            if (f.geometry == g) {
                t = f.time_s;
                break;
            }
        const std::string what = fmt::format("at t = {:.3f} s the motion makes '{}' and '{}' intersect", t,
                                             geometry.surface_name(x.a), geometry.surface_name(x.b));
        if (m_request.strict)
            throw Error(loc, what + "; change the motion (touching is fine) or run without --strict");
        m_warn(loc.to_string() + ": " + what +
               "; form factors near the intersection are wrong (--strict refuses it)");
    }
}

}  // namespace radiosa
