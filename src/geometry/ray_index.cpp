#include "geometry/ray_index.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace radiosa {

namespace {

// One Embree device for the process: creating one costs more than most scenes' BVH.
RTCDevice shared_device() {
    static const RTCDevice device = [] {
        RTCDevice d = rtcNewDevice(nullptr);
        if (!d)
            throw std::runtime_error("Embree: no device (error " +
                                     std::to_string(rtcGetDeviceError(nullptr)) + ")");
        return d;
    }();
    return device;
}

// The float just above x (Embree prunes with float distances; they must never be too short).
float float_up(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}
float float_down(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

}  // namespace

struct RayIndex::Impl {
    std::vector<const Surface*> surfaces;
    std::vector<std::array<double, 6>> boxes;  // lo x, y, z, hi x, y, z, relative to `center`
    Vec3 center{0.0};
    double radius = 0.0;  // of a ball holding every box
    RTCScene scene = nullptr;

    // What one query carries through Embree to the intersect callback: Embree's context first,
    // so the callback can cast back to it.
    struct Query {
        RTCIntersectContext rtc;
        const Impl* index;
        const Ray* ray;  // the caller's ray, in double
        double shift;    // Embree's ray starts at ray->at(shift), relative to `center`
        double best;     // the nearest hit so far (ray parameter of the caller's ray)
        std::optional<Found> found;
    };

    static void bounds(const RTCBoundsFunctionArguments* args) {
        const Impl* self = static_cast<const Impl*>(args->geometryUserPtr);
        const std::array<double, 6>& b = self->boxes[args->primID];
        RTCBounds* o = args->bounds_o;
        o->lower_x = float_down(b[0]);
        o->lower_y = float_down(b[1]);
        o->lower_z = float_down(b[2]);
        o->upper_x = float_up(b[3]);
        o->upper_y = float_up(b[4]);
        o->upper_z = float_up(b[5]);
    }

    static void intersect(const RTCIntersectFunctionNArguments* args) {
        if (!args->valid[0]) return;
        Query* q = reinterpret_cast<Query*>(args->context);
        const int k = static_cast<int>(args->primID);
        // Ties at exactly `best` go to the lower surface index, as in a loop over the surfaces.
        const double limit = std::nextafter(q->best, std::numeric_limits<double>::infinity());
        const auto h = q->index->surfaces[static_cast<std::size_t>(k)]->intersect(*q->ray, 0.0, limit,
                                                                                  HitSide::FrontOnly);
        if (!h || (h->dist == q->best && q->found && q->found->surface < k)) return;
        q->best = h->dist;
        q->found = Found{k, *h};
        RTCRayHit* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
        // Generous in float: traversal rounding must not prune a box holding a nearer hit.
        rh->ray.tfar = float_up((h->dist - q->shift) * (1.0 + 1e-5) + 1e-5 * q->index->radius);
        rh->hit.geomID = args->geomID;
        rh->hit.primID = args->primID;
    }
};

RayIndex::RayIndex(const std::vector<const Surface*>& surfaces) : m(std::make_unique<Impl>()) {
    m->surfaces = surfaces;
    const int n = static_cast<int>(surfaces.size());
    std::vector<std::array<double, 6>> world(static_cast<std::size_t>(n));
    Vec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (int k = 0; k < n; ++k)
        for (int a = 0; a < 3; ++a) {
            Vec3 axis(0.0);
            axis[a] = 1.0;
            const auto [l, h] = surfaces[static_cast<std::size_t>(k)]->linear_range(axis, 0.0, 1.0, 0.0, 1.0);
            world[static_cast<std::size_t>(k)][a] = l;
            world[static_cast<std::size_t>(k)][a + 3] = h;
            lo[a] = std::min(lo[a], l);
            hi[a] = std::max(hi[a], h);
        }
    m->center = 0.5 * (lo + hi);
    m->radius = 0.5 * glm::length(hi - lo);
    // Padding covers float rounding of the boxes, the ray's start and its direction.
    const double pad = 1e-5 * m->radius + 1e-300;
    m->radius += 2 * pad;
    m->boxes.resize(world.size());
    for (std::size_t k = 0; k < world.size(); ++k)
        for (int a = 0; a < 3; ++a) {
            m->boxes[k][a] = world[k][a] - m->center[a] - pad;
            m->boxes[k][a + 3] = world[k][a + 3] - m->center[a] + pad;
        }

    RTCDevice device = shared_device();
    m->scene = rtcNewScene(device);
    rtcSetSceneFlags(m->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(m->scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(n));
    rtcSetGeometryUserData(geom, m.get());
    rtcSetGeometryBoundsFunction(geom, &Impl::bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, &Impl::intersect);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(m->scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(m->scene);
    if (const RTCError e = rtcGetDeviceError(device); e != RTC_ERROR_NONE)
        throw std::runtime_error("Embree could not build the ray index (error " + std::to_string(e) + ")");
}

RayIndex::~RayIndex() {
    if (m && m->scene) rtcReleaseScene(m->scene);
}

std::optional<RayIndex::Found> RayIndex::nearest_front(const Ray& ray) const {
    // Clip the ray to the ball holding every box: Embree then starts inside the scene.
    const Vec3 oc = ray.origin - m->center;
    const double a = glm::dot(ray.dir, ray.dir), b = glm::dot(oc, ray.dir),
                 c = glm::dot(oc, oc) - m->radius * m->radius;
    if (!(a > 0.0)) return std::nullopt;
    const double disc = b * b - a * c;
    if (!(disc >= 0.0)) return std::nullopt;
    const double root = std::sqrt(disc);
    const double t_out = (-b + root) / a;
    if (!(t_out > 0.0)) return std::nullopt;
    const double t_in = std::max(0.0, (-b - root) / a);

    Impl::Query q;
    rtcInitIntersectContext(&q.rtc);
    q.index = m.get();
    q.ray = &ray;
    q.shift = t_in;
    q.best = std::numeric_limits<double>::infinity();
    RTCRayHit rh;
    const Vec3 start = oc + t_in * ray.dir;
    rh.ray.org_x = static_cast<float>(start.x);
    rh.ray.org_y = static_cast<float>(start.y);
    rh.ray.org_z = static_cast<float>(start.z);
    rh.ray.dir_x = static_cast<float>(ray.dir.x);
    rh.ray.dir_y = static_cast<float>(ray.dir.y);
    rh.ray.dir_z = static_cast<float>(ray.dir.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m->scene, &q.rtc, &rh);
    return q.found;
}

}  // namespace radiosa
