#include "distribute/frames.h"

#include <fmt/format.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>

#include "cache/cache_file.h"
#include "distribute/tags.h"
#include "distribute/task_farm.h"
#include "distribute/worker.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/shading.h"
#include "util/bytes.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

void put_rgbs(ByteWriter& w, const std::vector<Rgb>& v) {
    w.u64(v.size());
    if (!v.empty()) w.f64_array(&v[0][0], 3 * v.size());
}
std::vector<Rgb> get_rgbs(ByteReader& r) {
    std::vector<Rgb> v(r.u64());
    if (v.size() > r.remaining() / 24) throw ByteReader::Truncated();
    if (!v.empty()) r.f64_array(&v[0][0], 3 * v.size());
    return v;
}
void put_vec(ByteWriter& w, const Vec3& v) { w.f64_array(&v[0], 3); }
Vec3 get_vec(ByteReader& r) {
    Vec3 v;
    r.f64_array(&v[0], 3);
    return v;
}

Bytes encode(const FrameOrder& o, const CacheKey& key) {
    ByteWriter w;
    w.u8(kOrderFrames);
    w.str(o.scene_path);
    w.raw(key.bytes.data(), key.bytes.size());
    w.i64(o.threads);
    w.i64(o.render.width);
    w.i64(o.render.height);
    w.i64(o.render.samples);
    w.u64(o.states.size());
    for (const auto& s : o.states) {
        put_rgbs(w, s.B);
        put_rgbs(w, s.E);
    }
    w.u64(o.frames.size());
    for (const auto& f : o.frames) {
        w.i64(f.frame);
        put_vec(w, f.camera.eye);
        put_vec(w, f.camera.look_at);
        put_vec(w, f.camera.up);
        w.f64_array(&f.camera.fov_deg, 1);
        w.i64(f.state);
    }
    return std::move(w.bytes());
}

FrameOrder decode(const Bytes& bytes, CacheKey* key) {
    ByteReader r(bytes.data(), bytes.size());
    r.u8();
    FrameOrder o;
    o.scene_path = r.str();
    for (auto& b : key->bytes) b = r.u8();
    o.threads = static_cast<int>(r.i64());
    o.render.width = static_cast<int>(r.i64());
    o.render.height = static_cast<int>(r.i64());
    o.render.samples = static_cast<int>(r.i64());
    o.states.resize(r.u64());
    for (auto& s : o.states) {
        s.B = get_rgbs(r);
        s.E = get_rgbs(r);
    }
    o.frames.resize(r.u64());
    for (auto& f : o.frames) {
        f.frame = static_cast<int>(r.i64());
        f.camera.eye = get_vec(r);
        f.camera.look_at = get_vec(r);
        f.camera.up = get_vec(r);
        r.f64_array(&f.camera.fov_deg, 1);
        f.state = static_cast<int>(r.i64());
    }
    return o;
}

// Renders an order's frames on one rank, keeping the node radiosities of the last state.
class FrameRenderer {
public:
    FrameRenderer(const SceneGeometry& geometry, const FrameOrder& order) : m_geo(geometry), m_order(order) {}

    RenderedFrame render(int k) {
        const FrameOrder::Frame& f = m_order.frames[static_cast<std::size_t>(k)];
        const Stopwatch clock;
        if (m_state != f.state) {
            const auto& s = m_order.states[static_cast<std::size_t>(f.state)];
            m_nodes = std::make_unique<NodeRadiosity>(m_geo, s.B, s.E);
            m_state = f.state;
        }
        const PinholeCamera cam(f.camera, m_order.render.width, m_order.render.height);
        auto image = std::make_shared<const Image>(render_image(m_geo, *m_nodes, cam, m_order.render));
        return {std::move(image), 0, clock.seconds()};
    }

private:
    const SceneGeometry& m_geo;
    const FrameOrder& m_order;
    std::unique_ptr<NodeRadiosity> m_nodes;
    int m_state = -1;
};

Bytes pack(const RenderedFrame& f) {
    ByteWriter w;
    w.f64_array(&f.render_s, 1);
    w.i64(f.image->width);
    w.i64(f.image->height);
    w.raw(f.image->rgb.data(), f.image->rgb.size() * sizeof(float));
    return std::move(w.bytes());
}

RenderedFrame unpack(std::span<const std::uint8_t> bytes, int rank) {
    ByteReader r(bytes.data(), bytes.size());
    RenderedFrame f;
    f.rank = rank;
    r.f64_array(&f.render_s, 1);
    auto image = std::make_shared<Image>();
    image->width = static_cast<int>(r.i64());
    image->height = static_cast<int>(r.i64());
    image->rgb.resize(3 * static_cast<std::size_t>(image->width) * image->height);
    const std::size_t size = image->rgb.size() * sizeof(float);
    std::memcpy(image->rgb.data(), r.take(size), size);
    f.image = std::move(image);
    return f;
}

// Frames back in order: early ones wait here until every frame before them has been emitted.
class Reorder {
public:
    Reorder(const std::function<void(int, RenderedFrame)>& emit, int window)
        : m_emit(emit), m_window(window) {}

    void add(int k, RenderedFrame f) {
        std::lock_guard lock(m_mutex);
        m_waiting.emplace(k, std::move(f));
        while (!m_waiting.empty() && m_waiting.begin()->first == m_next) {
            m_emit(m_next, std::move(m_waiting.begin()->second));
            m_waiting.erase(m_waiting.begin());
            m_next.fetch_add(1);
        }
    }
    bool ready(int k) const { return k < m_next.load() + m_window; }

private:
    const std::function<void(int, RenderedFrame)>& m_emit;
    const int m_window;
    std::mutex m_mutex;
    std::map<int, RenderedFrame> m_waiting;
    std::atomic<int> m_next = 0;
};

}  // namespace

void render_frames_across(Cluster& cluster, const Scene& scene, const SceneGeometry& geometry,
                          const FrameOrder& order, const std::function<void(int, RenderedFrame)>& emit,
                          int window) {
    FrameOrder sent = order;
    sent.scene_path = std::filesystem::absolute(order.scene_path).string();
    const Bytes bytes = encode(sent, geometry_key(scene));
    for (int r = 1; r < cluster.size(); ++r) cluster.send(r, kTagOrder, bytes);
    FrameRenderer here(geometry, order);
    Reorder reorder(emit, std::max(window, cluster.size()));
    run_farm(cluster, {static_cast<int>(order.frames.size()), [&](int k) { reorder.add(k, here.render(k)); },
                       [&](int k, int rank, std::span<const std::uint8_t> result) {
                           reorder.add(k, unpack(result, rank));
                       },
                       [&](int k) { return reorder.ready(k); }});
}

void serve_frames(Cluster& cluster, const Bytes& bytes) {
    CacheKey key;
    const FrameOrder order = decode(bytes, &key);
    const WorkerThreads limit(order.threads);
    const Scene scene = load_worker_scene(cluster, order.scene_path, key);
    const SceneGeometry geometry(scene);
    FrameRenderer renderer(geometry, order);
    serve_farm(cluster, [&](int k) { return pack(renderer.render(k)); });
}

}  // namespace radiosa
