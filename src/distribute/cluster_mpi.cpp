// The cluster over MPI (Open MPI through its C API; the C++ bindings are deprecated).
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "distribute/cluster.h"
#include "util/error.h"

namespace radiosa {

namespace {

Cluster* g_cluster = nullptr;

// Started by mpirun (or another launcher of the PMI family)? A plain `radiosa ...` never calls
// MPI_Init: a singleton MPI start costs time and would try to reach a runtime daemon.
bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
        if (std::getenv(v)) return true;
    return false;
}

int source_of(int from) { return from == Cluster::kAny ? MPI_ANY_SOURCE : from; }
int tag_of(int tag) { return tag == Cluster::kAny ? MPI_ANY_TAG : tag; }

}  // namespace

Cluster& Cluster::start(int* argc, char*** argv) {
    if (g_cluster) return *g_cluster;
    if (!launched_by_mpi()) return current();
    // Rank 0 serves other ranks from a second thread while its main thread computes; the two
    // never call MPI at the same time, which is what MPI_THREAD_SERIALIZED allows.
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
    if (provided < MPI_THREAD_SERIALIZED) {
        std::cerr << "error: this MPI library does not support threads (MPI_THREAD_SERIALIZED); radiosa "
                     "needs it to serve other ranks while computing\n";
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    // An error in one rank's MPI call ends the job with MPI's message (the default handler).
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    static Cluster cluster(rank, size);
    g_cluster = &cluster;
    return cluster;
}

Cluster& Cluster::current() {
    if (g_cluster) return *g_cluster;
    static Cluster one(0, 1);
    return one;
}

void Cluster::send(int to, int tag, const Bytes& bytes) {
    if (bytes.size() > static_cast<std::size_t>(INT_MAX))
        throw Error("a message of " + std::to_string(bytes.size()) +
                    " bytes is more than MPI can send at once");
    MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}

std::optional<Cluster::Message> Cluster::try_receive(int from, int tag) {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(source_of(from), tag_of(tag), MPI_COMM_WORLD, &flag, &status);
    if (!flag) return std::nullopt;
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    Message m{status.MPI_SOURCE, status.MPI_TAG, Bytes(static_cast<std::size_t>(count))};
    MPI_Recv(m.bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    return m;
}

Cluster::Message Cluster::receive(int from, int tag) {
    // Open MPI's blocking receive spins on its core; this waits in short sleeps instead
    // (20 us growing to 1 ms), so a waiting rank costs nothing to the ones computing.
    auto pause = std::chrono::microseconds(20);
    for (;;) {
        if (auto m = try_receive(from, tag)) return std::move(*m);
        std::this_thread::sleep_for(pause);
        pause = std::min(pause * 2, std::chrono::microseconds(1000));
    }
}

void Cluster::abort(const std::string& message, int code) {
    std::cerr << "error: " << message << "\n" << std::flush;
    if (m_size > 1) MPI_Abort(MPI_COMM_WORLD, code);
    std::_Exit(code);
}

void Cluster::finish() {
    if (g_cluster != this) return;
    MPI_Finalize();
    g_cluster = nullptr;
}

std::string mpi_build_description() {
    char version[MPI_MAX_LIBRARY_VERSION_STRING];
    int length = 0;
    MPI_Get_library_version(version, &length);
    std::string v(version, static_cast<std::size_t>(std::max(length, 0)));
    v = v.substr(0, v.find_first_of(",\n"));
    return "yes (" + v + "; run it with mpirun -np N)";
}

}  // namespace radiosa
