// A cluster of one process: the build without MPI (-DRADIOSA_MPI=OFF).
#include <cstdlib>
#include <iostream>

#include "distribute/cluster.h"
#include "util/error.h"

namespace radiosa {

Cluster& Cluster::start(int*, char***) { return current(); }

Cluster& Cluster::current() {
    static Cluster one(0, 1);
    return one;
}

void Cluster::send(int, int, const Bytes&) {
    throw Error("internal: a message to another rank in a single process");
}

Cluster::Message Cluster::receive(int, int) {
    throw Error("internal: waiting for another rank in a single process");
}

std::optional<Cluster::Message> Cluster::try_receive(int, int) { return std::nullopt; }

void Cluster::abort(const std::string& message, int code) {
    std::cerr << "error: " << message << "\n";
    std::_Exit(code);
}

void Cluster::finish() {}

std::string mpi_build_description() { return "no, built with -DRADIOSA_MPI=OFF"; }

}  // namespace radiosa
