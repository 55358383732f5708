#include "distribute/task_farm.h"

#include <atomic>
#include <chrono>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

#include "distribute/tags.h"
#include "util/bytes.h"

namespace radiosa {

namespace {

// A request: u8 1 if a result follows (then i64 task, then the result's bytes), else u8 0.
Bytes request(int k, const Bytes& result) {
    ByteWriter w;
    w.u8(k >= 0 ? 1 : 0);
    if (k >= 0) {
        w.i64(k);
        w.raw(result.data(), result.size());
    }
    return std::move(w.bytes());
}

Bytes assignment(int k) {
    ByteWriter w;
    w.i64(k);
    return std::move(w.bytes());
}

// Hands tasks to the other ranks from rank 0's second thread.
class Dispatcher {
public:
    Dispatcher(Cluster& cluster, const FarmRoles& roles, std::atomic<int>* next)
        : m_cluster(cluster), m_roles(roles), m_next(next) {}

    void run() {
        auto pause = std::chrono::microseconds(20);
        while (m_finished < m_cluster.size() - 1) {
            bool progressed = false;
            if (auto m = m_cluster.try_receive(Cluster::kAny, kTagFarmRequest)) {
                take(*m);
                m_waiting.push_back(m->from);
                progressed = true;
            }
            if (assign()) progressed = true;
            if (progressed) {
                pause = std::chrono::microseconds(20);
            } else {
                std::this_thread::sleep_for(pause);
                pause = std::min(pause * 2, std::chrono::microseconds(1000));
            }
        }
    }
    std::exception_ptr error() const { return m_error; }

private:
    void take(const Cluster::Message& m) {
        ByteReader r(m.bytes.data(), m.bytes.size());
        if (r.u8() == 0) return;
        const int k = static_cast<int>(r.i64());
        if (m_error) return;  // after a failure: drain, do not process
        try {
            m_roles.take(k, m.from, std::span(m.bytes).subspan(r.pos()));
        } catch (...) {
            m_error = std::current_exception();
            m_next->store(m_roles.count);  // no more tasks for anyone
        }
    }
    // Answers the waiting ranks it can; false when none could be answered.
    bool assign() {
        bool any = false;
        while (!m_waiting.empty()) {
            int k = m_next->load();
            if (k < m_roles.count && m_roles.ready && !m_roles.ready(k)) break;
            if (k < m_roles.count && !m_next->compare_exchange_strong(k, k + 1)) continue;
            const int rank = m_waiting.front();
            m_waiting.pop_front();
            if (k >= m_roles.count) {
                m_cluster.send(rank, kTagFarmAssign, assignment(-1));
                ++m_finished;
            } else {
                m_cluster.send(rank, kTagFarmAssign, assignment(k));
            }
            any = true;
        }
        return any;
    }

    Cluster& m_cluster;
    const FarmRoles& m_roles;
    std::atomic<int>* m_next;
    std::deque<int> m_waiting;
    int m_finished = 0;
    std::exception_ptr m_error;
};

}  // namespace

void run_farm(Cluster& cluster, const FarmRoles& roles) {
    std::atomic<int> next = 0;
    Dispatcher dispatcher(cluster, roles, &next);
    std::thread serving;
    if (cluster.distributed()) serving = std::thread([&] { dispatcher.run(); });
    std::exception_ptr local_error;
    try {
        for (;;) {
            int k = next.load();
            if (k >= roles.count) break;
            if (roles.ready && !roles.ready(k)) {
                std::this_thread::sleep_for(std::chrono::microseconds(200));
                continue;
            }
            if (!next.compare_exchange_strong(k, k + 1)) continue;
            roles.local(k);
        }
    } catch (...) {
        local_error = std::current_exception();
        next.store(roles.count);
    }
    if (serving.joinable()) serving.join();
    if (local_error) std::rethrow_exception(local_error);
    if (dispatcher.error()) std::rethrow_exception(dispatcher.error());
}

void serve_farm(Cluster& cluster, const std::function<Bytes(int k)>& work) {
    int k = -1;
    Bytes result;
    for (;;) {
        cluster.send(0, kTagFarmRequest, request(k, result));
        const Cluster::Message m = cluster.receive(0, kTagFarmAssign);
        ByteReader r(m.bytes.data(), m.bytes.size());
        k = static_cast<int>(r.i64());
        if (k < 0) return;
        result = work(k);
    }
}

}  // namespace radiosa
