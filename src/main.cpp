#include <iostream>

#include "app/cli.h"
#include "distribute/cluster.h"
#include "distribute/worker.h"

// One process runs the command. In an MPI job (mpirun -np N build/radiosa ...), rank 0 runs it
// and the other ranks serve it until it ends (docs/distributed.md).
int main(int argc, char** argv) {
    radiosa::Cluster& cluster = radiosa::Cluster::start(&argc, &argv);
    if (cluster.rank() > 0) {
        const int code = radiosa::serve_orders(cluster);
        cluster.finish();
        return code;
    }
    const int code = radiosa::run_cli(argc, argv, std::cout, std::cerr);
    radiosa::release_workers(cluster);
    cluster.finish();
    return code;
}
