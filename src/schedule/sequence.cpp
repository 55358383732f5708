#include "schedule/sequence.h"

#include <algorithm>
#include <array>

#include "geometry/scene_geometry.h"

namespace radiosa {

namespace {

// What is interpolated: for orbit keys (D, theta, phi, look_at, up, fov), otherwise
// (eye, look_at, up, fov).
using Params = std::array<double, 10>;

Params params_of(const CameraKey& k, bool orbit) {
    const CameraDesc& c = k.camera;
    if (orbit)
        return {k.distance,  k.theta_deg, k.phi_deg, c.look_at.x, c.look_at.y,
                c.look_at.z, c.up.x,      c.up.y,    c.up.z,      c.fov_deg};
    return {c.eye.x,     c.eye.y, c.eye.z, c.look_at.x, c.look_at.y,
            c.look_at.z, c.up.x,  c.up.y,  c.up.z,      c.fov_deg};
}

CameraDesc camera_of(const Params& p, bool orbit) {
    CameraDesc c;
    c.look_at = Vec3(p[3], p[4], p[5]);
    c.up = Vec3(p[6], p[7], p[8]);
    c.fov_deg = p[9];
    c.eye = orbit ? orbit_position(c.look_at, p[0], p[1], p[2]) : Vec3(p[0], p[1], p[2]);
    return c;
}

struct Knot {
    double t;
    Params v;
    bool hold;  // one end of a hold: the camera rests here (zero tangent)
};

}  // namespace

CameraDesc Sequence::camera_at(double t) const {
    // The run of keys (between cuts) in force at time t.
    std::size_t first = 0;
    for (std::size_t k = 1; k < keys.size(); ++k)
        if (keys[k].cut && keys[k].time_s <= t) first = k;
    std::size_t last = first + 1;
    while (last < keys.size() && !keys[last].cut) ++last;

    bool orbit = true;
    for (std::size_t k = first; k < last; ++k) orbit = orbit && keys[k].orbit;
    std::vector<Knot> knots;
    for (std::size_t k = first; k < last; ++k) {
        const Params v = params_of(keys[k], orbit);
        knots.push_back({keys[k].time_s, v, keys[k].hold_s > 0.0});
        if (keys[k].hold_s > 0.0) knots.push_back({keys[k].time_s + keys[k].hold_s, v, true});
    }
    if (t <= knots.front().t || knots.size() == 1) return camera_of(knots.front().v, orbit);
    if (t >= knots.back().t) return camera_of(knots.back().v, orbit);
    std::size_t i = 0;
    while (knots[i + 1].t < t) ++i;
    const Knot& a = knots[i];
    const Knot& b = knots[i + 1];
    const double h = b.t - a.t, u = (t - a.t) / h;
    Params out{};
    if (interpolation == CameraInterpolation::ConstantSpeed) {
        for (std::size_t c = 0; c < out.size(); ++c) out[c] = a.v[c] + u * (b.v[c] - a.v[c]);
        return camera_of(out, orbit);
    }
    // Cubic Hermite with Catmull-Rom tangents weighted by the knots' times; zero at holds,
    // one-sided at the ends of the run.
    auto tangent = [&](std::size_t k, std::size_t c) {
        if (knots[k].hold) return 0.0;
        const std::size_t lo = k == 0 ? k : k - 1, hi = k + 1 == knots.size() ? k : k + 1;
        return (knots[hi].v[c] - knots[lo].v[c]) / (knots[hi].t - knots[lo].t);
    };
    const double u2 = u * u, u3 = u2 * u;
    const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    for (std::size_t c = 0; c < out.size(); ++c)
        out[c] = h00 * a.v[c] + h10 * h * tangent(i, c) + h01 * b.v[c] + h11 * h * tangent(i + 1, c);
    return camera_of(out, orbit);
}

Materials Sequence::materials_at(const Materials& base, const SceneGeometry& geometry, double t) const {
    Materials m = base;
    for (const SequenceEvent& ev : events) {
        if (t < ev.t0) continue;
        // A ramp starts from whatever the patch had when it started (earlier events applied).
        const double u = ev.t1 > ev.t0 ? std::min(1.0, (t - ev.t0) / (ev.t1 - ev.t0)) : 1.0;
        auto apply = [&](int i) {
            Rgb& slot = ev.property == EventProperty::Emission ? m.E[i] : m.rho[i];
            slot = u >= 1.0 ? ev.value : slot + u * (ev.value - slot);
        };
        if (ev.property == EventProperty::Motion) continue;
        if (ev.patch) {
            apply(geometry.patch_index(ev.surface, ev.patch->first, ev.patch->second));
        } else {
            for (int it = 0; it < geometry.nt(ev.surface); ++it)
                for (int is = 0; is < geometry.ns(ev.surface); ++is)
                    apply(geometry.patch_index(ev.surface, is, it));
        }
    }
    return m;
}

bool Sequence::has_motion() const {
    return std::any_of(events.begin(), events.end(),
                       [](const SequenceEvent& e) { return e.property == EventProperty::Motion; });
}

std::vector<Similarity> Sequence::motion_at(int surface_count, double t) const {
    struct State {
        Vec3 translate{0.0};
        EventRotation rotate;
    };
    std::vector<State> state(static_cast<std::size_t>(surface_count));
    for (const SequenceEvent& ev : events) {
        if (ev.property != EventProperty::Motion || ev.surface < 0 || t < ev.t0) continue;
        // A ramp goes from the displacement the surface has when it starts (earlier events
        // applied) to the one given; the reader allows one axis and centre per surface, so the
        // angle alone is interpolated (several turns are several turns).
        const double u = ev.t1 > ev.t0 ? std::min(1.0, (t - ev.t0) / (ev.t1 - ev.t0)) : 1.0;
        State& s = state[static_cast<std::size_t>(ev.surface)];
        if (ev.translate)
            s.translate = u >= 1.0 ? *ev.translate : s.translate + u * (*ev.translate - s.translate);
        if (ev.rotate) {
            const double a = s.rotate.angle_deg;
            s.rotate = *ev.rotate;
            s.rotate.angle_deg = u >= 1.0 ? ev.rotate->angle_deg : a + u * (ev.rotate->angle_deg - a);
        }
    }
    std::vector<Similarity> out(state.size());
    for (std::size_t k = 0; k < state.size(); ++k) {
        // x -> R (x - about) + about + translate: exactly the identity at angle 0 and no
        // translation (rotation_deg(axis, 0) is I to the bit).
        const State& s = state[k];
        out[k].rotate = rotation_deg(s.rotate.axis, s.rotate.angle_deg);
        out[k].translate = s.rotate.about - out[k].rotate * s.rotate.about + s.translate;
    }
    return out;
}

}  // namespace radiosa
