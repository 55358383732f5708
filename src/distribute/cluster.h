#pragma once
// The processes of one run: a single process, or the ranks of an MPI job
// (`mpirun -np N build/radiosa ...`, docs/distributed.md). Rank 0 runs the command as a single
// process would: it alone reads the command line, reports, checks and writes. The other ranks
// serve it (worker.h): they wait for work orders and send their results back. Messages are byte
// buffers with a tag; waiting polls and sleeps rather than spinning, so an idle rank leaves its
// core to the ranks that compute.
//
// cluster_mpi.cpp implements this with Open MPI (built with -DRADIOSA_MPI=ON, the default when
// MPI is found), cluster_single.cpp without it: a cluster of one process.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace radiosa {

using Bytes = std::vector<std::uint8_t>;

class Cluster {
public:
    static constexpr int kAny = -1;
    struct Message {
        int from = 0;
        int tag = 0;
        Bytes bytes;
    };

    // Joins the MPI job when the process was started by mpirun (and the build has MPI);
    // otherwise a cluster of one. Call once, first thing in main.
    static Cluster& start(int* argc, char*** argv);
    // The cluster start() made; a cluster of one when start() was never called (tests).
    static Cluster& current();

    int rank() const { return m_rank; }
    int size() const { return m_size; }
    bool distributed() const { return m_size > 1; }

    void send(int to, int tag, const Bytes& bytes);
    // The next message from `from` with `tag` (kAny: any), waiting as long as it takes.
    Message receive(int from, int tag);
    std::optional<Message> try_receive(int from, int tag);
    // Prints "error: <message>" on stderr and ends every rank of the job with `code`.
    [[noreturn]] void abort(const std::string& message, int code);
    // Leaves the MPI job (MPI_Finalize); no message may be sent after it.
    void finish();

private:
    Cluster(int rank, int size) : m_rank(rank), m_size(size) {}
    int m_rank = 0, m_size = 1;
};

// "yes (Open MPI ...)" or "no, built with -DRADIOSA_MPI=OFF", for --version.
std::string mpi_build_description();

}  // namespace radiosa
