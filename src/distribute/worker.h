#pragma once
// Every rank but 0 of an MPI job: waits for work orders from rank 0 and carries them out. An
// order names the files to read (every rank must see the same files, as on any cluster with a
// shared file system) and what to compute; the rank never writes a file and never reports,
// so bad input is reported once, by rank 0.
#include <tbb/global_control.h>

#include <memory>
#include <string>

#include "cache/cache_file.h"
#include "distribute/cluster.h"
#include "scene/scene.h"

namespace radiosa {

enum OrderKind : std::uint8_t { kOrderExit = 0, kOrderFormFactors = 1, kOrderFrames = 2 };

// Serves orders until rank 0 says exit; returns the process's exit code. A rank that cannot
// carry out an order (a file it cannot read, out of memory) ends the job with a message.
int serve_orders(Cluster& cluster);

// Rank 0, when its command ends (however it ends): tells every other rank to exit.
void release_workers(Cluster& cluster);

// The identity of a scene's geometry: the cache key of its default form factors (it hashes
// every surface). Rank 0 sends it with each order.
CacheKey geometry_key(const Scene& scene);

// The scene at `path`, checked to be the geometry rank 0 read (`geometry`); otherwise the job
// ends with "rank r: <why>".
Scene load_worker_scene(Cluster& cluster, const std::string& path, const CacheKey& geometry);

// Limits this rank's threads to what rank 0 uses (0: all cores) for the order's duration.
class WorkerThreads {
public:
    explicit WorkerThreads(int threads);
    ~WorkerThreads();

private:
    std::unique_ptr<tbb::global_control> m_control;
};

}  // namespace radiosa
