#include "geometry/ray_index.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "geometry/ball_hits_avx512.h"
#include "surfaces/sphere_hit.h"

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

// std::nextafter(x, +inf) for finite x, inline (the library call was 2 % of a frame): the
// neighbour one unit in the last place up, through the bits' order.
template <class F, class U>
F next_up(F x) {
    if (x == F(0)) return std::numeric_limits<F>::denorm_min();
    const U bits = std::bit_cast<U>(x);
    return std::bit_cast<F>(x > F(0) ? bits + 1 : bits - 1);
}
double next_up(double x) { return next_up<double, std::uint64_t>(x); }
float next_up(float x) { return next_up<float, std::uint32_t>(x); }

// The float just above x (Embree prunes with float distances; they must never be too short).
float float_up(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x) f = next_up(f);
    return f;
}
float float_down(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = -next_up(-f);
    return f;
}

}  // namespace

struct RayIndex::Impl {
    std::vector<const Surface*> surfaces;
    std::vector<std::array<double, 6>> boxes;  // lo x, y, z, hi x, y, z, relative to `center`
    // Whole spheres, tested inline by the test their type uses (surfaces/sphere_hit.h): the
    // commonest candidates of a crowded scene, without a virtual call each. Radius 0: another
    // surface.
    std::vector<Surface::Ball> balls;
    Vec3 center{0.0};
    double radius = 0.0;  // of a ball holding every box
    RTCScene scene = nullptr;

    // One ray of a query: the caller's ray in double, and the nearest hit so far.
    struct Lane {
        const Ray* ray = nullptr;
        double shift = 0.0;  // Embree's ray starts at ray->at(shift), relative to `center`
        double best = std::numeric_limits<double>::infinity();  // ray parameter of the caller's ray
        int surface = -1;                                       // whose front side is hit at `best`
        double limit = 0.0;  // the t_max it was found with (a numeric root may depend on it)
        // The t_max for the next candidate: just above `best`, so that a tie at exactly
        // `best` is found and goes to the lower surface index, as in a loop over the surfaces.
        double next = std::numeric_limits<double>::infinity();
    };
    // What one query (a ray, or a packet of up to kPacket) carries through Embree to the
    // intersect callback: Embree's context first, so the callback can cast back to it. Embree
    // may regroup a packet's rays before a callback, so each ray's id names its lane.
    // Packets of 16 rays where the processor has AVX-512 (Embree's native width there), else 8.
    static constexpr int kPacket = 16;
    // A packet's rays by coordinate: ray[0..2][i] lane i's direction, ray[3..5][i] its origin.
    struct PacketRays {
        alignas(64) double ray[6][kPacket];
    };
    struct Query {
        RTCIntersectContext rtc;
        const Impl* index;
        Lane* lanes;                      // the packet's, lanes[id]
        const PacketRays* soa = nullptr;  // set for a packet of 16 (AVX-512)
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

    // Lane i's ray meets surface `args->primID` at d, below its t_max: the nearest so far.
    static void take(const RTCIntersectFunctionNArguments* args, const Query* q, unsigned i, Lane& l,
                     double d) {
        const int k = static_cast<int>(args->primID);
        if (d == l.best && l.surface < k) return;
        l.best = d;
        l.surface = k;
        l.limit = l.next;
        l.next = next_up(d);  // d is finite: it is below l.next
        // Generous in float: traversal rounding must not prune a box holding a nearer hit.
        const unsigned n = args->N;
        RTCRayN_tfar(RTCRayHitN_RayN(args->rayhit, n), n, i) =
            float_up((d - l.shift) * (1.0 + 1e-5) + 1e-5 * q->index->radius);
        RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, n);
        RTCHitN_geomID(hits, n, i) = args->geomID;
        RTCHitN_primID(hits, n, i) = args->primID;
    }

#if defined(__x86_64__)
    // A whole sphere against a packet of 16 in the order it was traced (lane i is ray i): eight
    // lanes at a time straight from the packet's coordinates, no gathering. False (nothing
    // done) when Embree has regrouped the packet.
    static bool test_by_coordinate(const RTCIntersectFunctionNArguments* args, const Query* q,
                                   const Surface::Ball& ball) {
        RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
        for (unsigned i = 0; i < kPacket; ++i)
            if (args->valid[i] && RTCRayN_id(rays, args->N, i) != i) return false;
        const double center[3] = {ball.center.x, ball.center.y, ball.center.z};
        for (unsigned h = 0; h < kPacket; h += 8) {
            unsigned any = 0;
            double limit[8], d[8];
            for (unsigned r = 0; r < 8; ++r) {
                any |= static_cast<unsigned>(args->valid[h + r]);
                limit[r] = q->lanes[h + r].next;
            }
            if (!any) continue;
            const double* const ray[6] = {q->soa->ray[0] + h, q->soa->ray[1] + h, q->soa->ray[2] + h,
                                          q->soa->ray[3] + h, q->soa->ray[4] + h, q->soa->ray[5] + h};
            sphere_front_distance8(ray, center, ball.radius, ball.orientation, limit, d);
            for (unsigned r = 0; r < 8; ++r)
                if (args->valid[h + r] && d[r] < q->lanes[h + r].next)
                    take(args, q, h + r, q->lanes[h + r], d[r]);
        }
        return true;
    }
#endif

    static void intersect(const RTCIntersectFunctionNArguments* args) {
        Query* q = reinterpret_cast<Query*>(args->context);
        const unsigned n = args->N;
        RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, n);
        const int k = static_cast<int>(args->primID);
        const Surface::Ball& ball = q->index->balls[static_cast<std::size_t>(k)];
        if (ball.radius > 0.0) {
            // A whole sphere: a packet of 16 eight lanes at a time (AVX-512), else its valid
            // lanes four at a time (AVX; the last group filled up with copies), else one at a
            // time, by the same operations, so the same bits (surfaces/sphere_hit.h).
#if defined(__x86_64__)
            if (q->soa && n == kPacket && test_by_coordinate(args, q, ball)) return;
#endif
            unsigned lane[kPacket];
            unsigned m = 0;
            for (unsigned i = 0; i < n; ++i)
                if (args->valid[i]) lane[m++] = i;
            unsigned j = 0;
#if defined(__x86_64__)
            static const bool avx = __builtin_cpu_supports("avx");
            for (; avx && m > 1 && j < m; j += 4) {
                const Ray* four[4];
                double limit[4], d[4];
                unsigned ids[4];
                for (unsigned r = 0; r < 4; ++r) {
                    ids[r] = lane[j + r < m ? j + r : j];
                    const Lane& l = q->lanes[RTCRayN_id(rays, n, ids[r])];
                    four[r] = l.ray;
                    limit[r] = l.next;
                }
                sphere_front_distance4(four, ball.center, ball.radius, ball.orientation, limit, d);
                for (unsigned r = 0; r < 4 && j + r < m; ++r) {
                    Lane& l = q->lanes[RTCRayN_id(rays, n, ids[r])];
                    if (d[r] < l.next) take(args, q, ids[r], l, d[r]);
                }
            }
#endif
            for (; j < m; ++j) {  // one ray (rtcIntersect1), or no AVX
                Lane& l = q->lanes[RTCRayN_id(rays, n, lane[j])];
                const double d =
                    sphere_front_distance(*l.ray, ball.center, ball.radius, ball.orientation, 0.0, l.next);
                if (d < l.next) take(args, q, lane[j], l, d);
            }
            return;
        }
        const Surface& surface = *q->index->surfaces[static_cast<std::size_t>(k)];
        for (unsigned i = 0; i < n; ++i) {
            if (!args->valid[i]) continue;
            Lane& l = q->lanes[RTCRayN_id(rays, n, i)];
            if (const auto d = surface.front_distance(*l.ray, 0.0, l.next)) take(args, q, i, l, *d);
        }
    }

    // The nearest surface's hit of one ray into *out (surface -1: none), by that surface's
    // intersect(), which Surface promises gives the distance front_distance gave, bit for bit;
    // should a type ever break that, the loop decides.
    void finish(const Lane& l, Found* out) const {
        out->surface = -1;
        if (l.surface < 0) return;
        if (const auto h = surfaces[static_cast<std::size_t>(l.surface)]->intersect(*l.ray, 0.0, l.limit,
                                                                                    HitSide::FrontOnly);
            h && h->dist == l.best) {
            out->surface = l.surface;
            out->hit = *h;
        } else {
            by_loop(*l.ray, out);
        }
    }
    // The same for n lanes of packets, into out[i]: each surface finds the hits of its lanes
    // together (Surface::front_hits: a whole sphere's angles in SIMD lanes).
    void finish(const Lane* lanes, std::size_t n, Found* out) const {
        constexpr std::size_t kMax = 64;
        const Ray* rays[kMax];
        double dist[kMax], limit[kMax];
        std::optional<SurfaceHit> hits[kMax];
        // Runs of neighbouring lanes on the same surface (a ball's pixels in a row) go together.
        for (std::size_t i = 0; i < n;) {
            const int k = lanes[i].surface;
            std::size_t j = i;
            for (; j < n && j - i < kMax && lanes[j].surface == k; ++j) {
                rays[j - i] = lanes[j].ray;
                dist[j - i] = lanes[j].best;
                limit[j - i] = lanes[j].limit;
            }
            if (k >= 0) surfaces[static_cast<std::size_t>(k)]->front_hits(j - i, rays, dist, limit, hits);
            for (std::size_t r = i; r < j; ++r) {
                Found& f = out[r];
                f.surface = -1;
                if (k < 0) continue;
                if (const auto& h = hits[r - i]; h && h->dist == lanes[r].best) {
                    f.surface = k;
                    f.hit = *h;
                } else {
                    by_loop(*lanes[r].ray, &f);
                }
            }
            i = j;
        }
    }
    template <int K, class RayHitK>
    void trace(const Ray* rays, std::size_t count, Found* found) const;
    void by_loop(const Ray& ray, Found* out) const {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < surfaces.size(); ++k)
            if (const auto g = surfaces[k]->intersect(ray, 0.0, best, HitSide::FrontOnly)) {
                best = g->dist;
                out->surface = static_cast<int>(k);
                out->hit = *g;
            }
    }

    // Sets up lane l for `ray`, clipped to the ball holding every box (Embree then starts
    // inside the scene); false when the ray misses that ball (l.surface then -1).
    bool start(const Ray& ray, Lane& l, Vec3* org) const {
        l.surface = -1;
        const Vec3 oc = ray.origin - center;
        const double a = glm::dot(ray.dir, ray.dir), b = glm::dot(oc, ray.dir),
                     c = glm::dot(oc, oc) - radius * radius;
        if (!(a > 0.0)) return false;
        l.shift = 0.0;  // a ray from inside the ball (a camera in the scene) starts where it is
        if (!(c < 0.0)) {
            const double disc = b * b - a * c;
            if (!(disc >= 0.0)) return false;
            const double root = std::sqrt(disc);
            const double t_out = (-b + root) / a;
            if (!(t_out > 0.0)) return false;
            l.shift = std::max(0.0, (-b - root) / a);
        }
        l.ray = &ray;
        l.best = l.next = std::numeric_limits<double>::infinity();
        *org = oc + l.shift * ray.dir;
        return true;
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
    m->balls.resize(surfaces.size());
    for (std::size_t k = 0; k < surfaces.size(); ++k)
        if (const auto b = surfaces[k]->front_distance_of_ball()) m->balls[k] = *b;
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
    Impl::Lane lane;
    Impl::Query q;
    q.lanes = &lane;
    Vec3 org;
    if (!m->start(ray, lane, &org)) return std::nullopt;
    rtcInitIntersectContext(&q.rtc);
    q.index = m.get();
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(org.x);
    rh.ray.org_y = static_cast<float>(org.y);
    rh.ray.org_z = static_cast<float>(org.z);
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
    Found f;
    m->finish(lane, &f);
    if (f.surface < 0) return std::nullopt;
    return f;
}

// Traces the rays in packets of K (rtcIntersect8 or 16), 64 rays at a time, whose nearest
// surfaces then find their hits together.
template <int K, class RayHitK>
void RayIndex::Impl::trace(const Ray* rays, std::size_t count, Found* found) const {
    static_assert(K <= kPacket);
    constexpr std::size_t kBlock = 64;
    Lane lanes[kBlock];
    PacketRays soa;
    Query q;
    q.index = this;
    q.soa = K == kPacket ? &soa : nullptr;
    for (std::size_t block = 0; block < count; block += kBlock) {
        const std::size_t in_block = std::min(kBlock, count - block);
        for (std::size_t first = 0; first < in_block; first += K) {
            const int n = static_cast<int>(std::min<std::size_t>(K, in_block - first));
            alignas(64) int valid[K];
            alignas(64) RayHitK rh;
            q.lanes = lanes + first;
            for (int i = 0; i < K; ++i) {
                const Ray* ray = i < n ? &rays[block + first + i] : nullptr;
                Vec3 org(0.0);
                valid[i] = ray && start(*ray, lanes[first + i], &org) ? -1 : 0;
                const Vec3 dir = ray ? ray->dir : Vec3(1.0, 0.0, 0.0);
                if constexpr (K == kPacket) {
                    const Vec3 at = ray ? ray->origin : Vec3(0.0);
                    for (int a = 0; a < 3; ++a) {
                        soa.ray[a][i] = dir[a];
                        soa.ray[3 + a][i] = at[a];
                    }
                }
                rh.ray.org_x[i] = static_cast<float>(org.x);
                rh.ray.org_y[i] = static_cast<float>(org.y);
                rh.ray.org_z[i] = static_cast<float>(org.z);
                rh.ray.dir_x[i] = static_cast<float>(dir.x);
                rh.ray.dir_y[i] = static_cast<float>(dir.y);
                rh.ray.dir_z[i] = static_cast<float>(dir.z);
                rh.ray.tnear[i] = 0.0f;
                rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
                rh.ray.time[i] = 0.0f;
                rh.ray.mask[i] = 0xFFFFFFFFu;
                rh.ray.id[i] = static_cast<unsigned>(i);
                rh.ray.flags[i] = 0;
                rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcInitIntersectContext(&q.rtc);
            q.rtc.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            if constexpr (K == 16)
                rtcIntersect16(valid, scene, &q.rtc, &rh);
            else
                rtcIntersect8(valid, scene, &q.rtc, &rh);
        }
        finish(lanes, in_block, found + block);
    }
}

void RayIndex::nearest_front(const Ray* rays, std::size_t count, Found* found, int packet) const {
#if defined(__x86_64__)
    static const bool avx512 = __builtin_cpu_supports("avx512f");
    if (avx512 && packet != 8) return m->trace<16, RTCRayHit16>(rays, count, found);
#endif
    m->trace<8, RTCRayHit8>(rays, count, found);
}

}  // namespace radiosa
