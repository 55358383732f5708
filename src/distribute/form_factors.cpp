#include "distribute/form_factors.h"

#include <tbb/info.h>

#include <filesystem>
#include <mutex>

#include "distribute/tags.h"
#include "distribute/task_farm.h"
#include "distribute/worker.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/bytes.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// Chunk boundaries 0 = b_0 < b_1 < ... < b_m = n: row i holds n - i pairs, so the first rows
// are the dearest; each chunk gets about total / (8 x ranks) pairs and at least `min_rows`
// rows (the threads of a rank), enough chunks for the dynamic hand-out to even out uneven pairs.
std::vector<int> chunk_bounds(int n, int ranks, int min_rows) {
    const double total = 0.5 * n * (n + 1.0);
    const double target = total / (8.0 * ranks);
    std::vector<int> b{0};
    double acc = 0.0;
    for (int i = 0; i < n; ++i) {
        acc += n - i;
        if ((acc >= target && i + 1 - b.back() >= min_rows) || i + 1 == n) {
            b.push_back(i + 1);
            acc = 0.0;
        }
    }
    return b;
}

struct Order {
    std::string scene_path;
    FormFactorOptions options;
    CacheKey key;  // geometry_key of the scene rank 0 read
    int threads = 0;
    std::vector<int> bounds;
};

Bytes encode(const Order& o) {
    ByteWriter w;
    w.u8(kOrderFormFactors);
    w.str(o.scene_path);
    w.u8(static_cast<std::uint8_t>(o.options.method));
    w.f64(o.options.tolerance);
    w.i64(o.options.gauss_points);
    w.u8(o.options.visibility);
    w.u8(o.options.culling);
    w.u8(o.options.numeric_lines);
    w.raw(o.key.bytes.data(), o.key.bytes.size());
    w.i64(o.threads);
    w.u32(static_cast<std::uint32_t>(o.bounds.size()));
    for (int b : o.bounds) w.i64(b);
    return std::move(w.bytes());
}

Order decode(const Bytes& bytes) {
    ByteReader r(bytes.data(), bytes.size());
    r.u8();
    Order o;
    o.scene_path = r.str();
    o.options.method = static_cast<FormFactorMethod>(r.u8());
    o.options.tolerance = r.f64();
    o.options.gauss_points = static_cast<int>(r.i64());
    o.options.visibility = r.u8() != 0;
    o.options.culling = r.u8() != 0;
    o.options.numeric_lines = r.u8() != 0;
    for (auto& b : o.key.bytes) b = r.u8();
    o.threads = static_cast<int>(r.i64());
    o.bounds.resize(r.u32());
    for (int& b : o.bounds) b = static_cast<int>(r.i64());
    return o;
}

// A chunk's result: its counts, its seconds per surface, then per row i the upper row F(i, i..n-1), the
// column F(i..n-1, i) and, when error-controlled, the same two of the estimates. Raw doubles: the bits rank 0
// stores are the bits this rank computed.
Bytes pack_rows(const FormFactors& ff, int begin, int end, const FormFactorStats& stats) {
    ByteWriter w;
    stats.for_each_counter([&](const char*, long long v) { w.i64(v); });
    w.i64(static_cast<std::int64_t>(stats.seconds_by_surface.size()));
    w.f64_array(stats.seconds_by_surface.data(), stats.seconds_by_surface.size());
    const int n = ff.F.n;
    std::vector<double> col;
    for (int i = begin; i < end; ++i) {
        const std::size_t len = static_cast<std::size_t>(n - i);
        w.f64_array(&ff.F.data[static_cast<std::size_t>(i) * n + i], len);
        col.resize(len);
        for (int j = i; j < n; ++j) col[static_cast<std::size_t>(j - i)] = ff.F(j, i);
        w.f64_array(col.data(), len);
        if (ff.error.empty()) continue;
        const std::size_t row = static_cast<std::size_t>(i) * n;
        w.f64_array(&ff.error[row + i], len);
        for (int j = i; j < n; ++j)
            col[static_cast<std::size_t>(j - i)] = ff.error[static_cast<std::size_t>(j) * n + i];
        w.f64_array(col.data(), len);
    }
    return std::move(w.bytes());
}

void unpack_rows(std::span<const std::uint8_t> bytes, int begin, int end, FormFactors* ff,
                 FormFactorStats* stats) {
    ByteReader r(bytes.data(), bytes.size());
    FormFactorStats add;
    add.for_each_counter([&](const char*, long long& v) { v = r.i64(); });
    const std::int64_t surfaces = r.i64();
    if (surfaces < 0 || static_cast<std::uint64_t>(surfaces) > r.remaining() / 8)
        throw ByteReader::Truncated();
    add.seconds_by_surface.resize(static_cast<std::size_t>(surfaces));
    r.f64_array(add.seconds_by_surface.data(), add.seconds_by_surface.size());
    *stats += add;
    const int n = ff->F.n;
    std::vector<double> v;
    auto read = [&](std::size_t len) {
        v.resize(len);
        r.f64_array(v.data(), len);
    };
    for (int i = begin; i < end; ++i) {
        const std::size_t len = static_cast<std::size_t>(n - i);
        read(len);
        for (int j = i; j < n; ++j) ff->F(i, j) = v[static_cast<std::size_t>(j - i)];
        read(len);
        for (int j = i; j < n; ++j) ff->F(j, i) = v[static_cast<std::size_t>(j - i)];
        if (ff->error.empty()) continue;
        read(len);
        for (int j = i; j < n; ++j)
            ff->error[static_cast<std::size_t>(i) * n + j] = v[static_cast<std::size_t>(j - i)];
        read(len);
        for (int j = i; j < n; ++j)
            ff->error[static_cast<std::size_t>(j) * n + i] = v[static_cast<std::size_t>(j - i)];
    }
}

FormFactors compute_across(Cluster& cluster, int threads, const Scene& scene, const SceneGeometry& geometry,
                           const FormFactorOptions& options) {
    const Stopwatch clock;
    Order order{std::filesystem::absolute(scene.file).string(), options, geometry_key(scene), threads, {}};
    const int n = geometry.patch_count();
    // At least one row per thread in a chunk, so that every thread of a rank has a row.
    order.bounds = chunk_bounds(n, cluster.size(), threads > 0 ? threads : tbb::info::default_concurrency());
    // Everything that can fail here (the n x n allocation) before the other ranks are told:
    // once they have the order, only run_farm may end it.
    const FormFactorRows rows(geometry, options);
    FormFactors ff = rows.zeros();
    const Bytes bytes = encode(order);
    for (int r = 1; r < cluster.size(); ++r) cluster.send(r, kTagOrder, bytes);

    FormFactorStats here, there;
    const int chunks = static_cast<int>(order.bounds.size()) - 1;
    run_farm(cluster, {chunks,
                       [&](int k) { rows.compute(order.bounds[k], order.bounds[k + 1], &ff, &here); },
                       [&](int k, int, std::span<const std::uint8_t> result) {
                           unpack_rows(result, order.bounds[k], order.bounds[k + 1], &ff, &there);
                       },
                       {}});
    ff.stats = here;
    ff.stats += there;
    ff.stats.seconds = clock.seconds();
    return ff;
}

}  // namespace

ComputeFormFactors form_factors_across(Cluster& cluster, int threads) {
    if (!cluster.distributed()) return {};
    return [&cluster, threads](const Scene& scene, const SceneGeometry& geometry,
                               const FormFactorOptions& options) {
        return compute_across(cluster, threads, scene, geometry, options);
    };
}

void serve_form_factors(Cluster& cluster, const Bytes& bytes) {
    const Order order = decode(bytes);
    const WorkerThreads limit(order.threads);
    const Scene scene = load_worker_scene(cluster, order.scene_path, order.key);
    const SceneGeometry geometry(scene);
    const FormFactorRows rows(geometry, order.options);
    FormFactors ff = rows.zeros();
    serve_farm(cluster, [&](int k) {
        FormFactorStats stats;
        rows.compute(order.bounds[k], order.bounds[k + 1], &ff, &stats);
        return pack_rows(ff, order.bounds[k], order.bounds[k + 1], stats);
    });
}

}  // namespace radiosa
