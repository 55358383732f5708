#pragma once
// Form factors across the ranks of an MPI job: rank 0 cuts the rows of the matrix into chunks
// of about equal pair counts, hands them out dynamically (task_farm.h), and puts the rows it
// gets back in place. Every row is computed exactly as a single process computes it, so the
// matrix is bit-identical for any number of ranks and threads. Rank 0 alone then checks,
// caches and reports it, as in one process.
#include <string>

#include "cache/cache_file.h"
#include "distribute/cluster.h"

namespace radiosa {

// The cache's compute hook for this cluster (rank 0): with one process, compute_form_factors.
// `threads` is what every rank uses (0: all its cores).
ComputeFormFactors form_factors_across(Cluster& cluster, int threads);

// A worker rank's side of one work order (worker.cpp): loads the scene the order names, checks
// that it is the same geometry rank 0 has, and computes the chunks it is handed.
void serve_form_factors(Cluster& cluster, const Bytes& order);

}  // namespace radiosa
