#include "distribute/worker.h"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <new>

#include "distribute/form_factors.h"
#include "distribute/frames.h"
#include "distribute/tags.h"
#include "util/error.h"

namespace radiosa {

WorkerThreads::WorkerThreads(int threads) {
    if (threads > 0)
        m_control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                          static_cast<std::size_t>(threads));
}
WorkerThreads::~WorkerThreads() = default;

CacheKey geometry_key(const Scene& scene) { return form_factor_key(scene, FormFactorOptions{}); }

Scene load_worker_scene(Cluster& cluster, const std::string& path, const CacheKey& geometry) {
    Scene scene;
    try {
        scene = load_scene(path);
    } catch (const Error& e) {
        cluster.abort(fmt::format("rank {}: {} (rank 0 read it; every rank must see the same files)",
                                  cluster.rank(), e.what()),
                      1);
    }
    if (!(geometry_key(scene) == geometry))
        cluster.abort(
            fmt::format("rank {}: {} is not the scene rank 0 read (its geometry differs): every rank "
                        "must see the same files",
                        cluster.rank(), path),
            1);
    return scene;
}

int serve_orders(Cluster& cluster) {
    for (;;) {
        const Cluster::Message m = cluster.receive(0, kTagOrder);
        const auto kind = m.bytes.empty() ? kOrderExit : static_cast<OrderKind>(m.bytes[0]);
        try {
            switch (kind) {
                case kOrderExit:
                    return 0;
                case kOrderFormFactors:
                    serve_form_factors(cluster, m.bytes);
                    break;
                case kOrderFrames:
                    serve_frames(cluster, m.bytes);
                    break;
                default:
                    cluster.abort(fmt::format("rank {}: unknown work order {}", cluster.rank(), int(kind)),
                                  2);
            }
        } catch (const std::bad_alloc&) {
            cluster.abort(fmt::format("rank {}: out of memory", cluster.rank()), 2);
        } catch (const std::exception& e) {
            cluster.abort(fmt::format("rank {}: {}", cluster.rank(), e.what()), 2);
        }
    }
}

void release_workers(Cluster& cluster) {
    const Bytes exit{kOrderExit};
    for (int r = 1; r < cluster.size(); ++r) cluster.send(r, kTagOrder, exit);
}

}  // namespace radiosa
