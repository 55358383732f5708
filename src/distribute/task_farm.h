#pragma once
// Shares tasks 0 .. count-1 out among the ranks, dynamically: whoever is free takes the next
// task, so very uneven tasks (a row of sphere-shadowed pairs against a row of closed forms, a
// frame of empty sky against a close-up) balance themselves. Rank 0 computes too, on its main
// thread, while a second thread serves the other ranks: each sends its last result with its
// request for the next task and gets a task number or "done" back.
//
// Rank 0 calls run_farm(); every other rank, told to join by a work order, calls
// serve_farm(). Results reach rank 0 in any order; `take` sees each exactly once.
#include <functional>
#include <span>

#include "distribute/cluster.h"

namespace radiosa {

struct FarmRoles {
    int count = 0;
    // Rank 0's own work on task k (its main thread).
    std::function<void(int k)> local;
    // A result another rank sent (rank 0's serving thread; never at the same time as another
    // take, but at the same time as `local`).
    std::function<void(int k, int rank, std::span<const std::uint8_t> result)> take;
    // May task k be handed out yet? (Bounds what waits on rank 0, e.g. frames ahead of the
    // encoder.) Called on either thread; must be thread-safe. Empty: always.
    std::function<bool(int k)> ready;
};

// Rank 0. Returns when every task is done and every result taken; rethrows the first
// exception `local` or `take` threw (after the other ranks have been told to stop).
void run_farm(Cluster& cluster, const FarmRoles& roles);

// Every other rank: computes the tasks rank 0 hands it with `work` until told it is done.
void serve_farm(Cluster& cluster, const std::function<Bytes(int k)>& work);

}  // namespace radiosa
