#pragma once
// Parallel loops for the file loaders, on std::thread rather than OpenMP: a process forked from
// one that has used OpenMP (a test runner, a server handing each file to a child) hangs in its
// first OpenMP parallel region, and loading a file in such a child is common. The thread count
// still follows OpenMP's setting (OMP_NUM_THREADS), so one knob governs the whole library.
#include <algorithm>
#include <cstdint>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace detail {

/** The threads a loader uses at most: OpenMP's setting, else the cores. */
inline int loaderThreads() {
#ifdef _OPENMP
  return std::max(1, omp_get_max_threads());
#else
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
#endif
}

/** Calls body(i) for every i in [0, count), each thread on its own contiguous range, with fewer
 *  threads than loaderThreads() when a thread would get fewer than `min_per_thread` items. The
 *  first exception by range order is rethrown once all threads have finished. */
template <class Body>
void parallelForInLoader(std::int64_t count, std::int64_t min_per_thread, const Body& body) {
  const std::int64_t max_threads = loaderThreads();
  const std::int64_t threads =
      std::clamp<std::int64_t>(count / std::max<std::int64_t>(1, min_per_thread), 1, max_threads);
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads));
  const auto run_range = [&](std::int64_t id) {
    try {
      for (std::int64_t i = count * id / threads; i < count * (id + 1) / threads; ++i) body(i);
    } catch (...) {
      errors[static_cast<std::size_t>(id)] = std::current_exception();
    }
  };
  std::vector<std::thread> helpers;
  helpers.reserve(static_cast<std::size_t>(threads - 1));
  for (std::int64_t id = 1; id < threads; ++id) {
    try {
      helpers.emplace_back(run_range, id);
    } catch (const std::system_error&) {
      run_range(id);  // no thread to be had: the range runs here
    }
  }
  run_range(0);
  for (std::thread& helper : helpers) helper.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace detail
}  // namespace pcl_ddg
