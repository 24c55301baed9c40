#pragma once
// Per-thread ranges of vertices, for passes that scatter per-triangle or per-edge data into
// per-vertex rows: every thread reads the whole input but writes only its own rows, so no atomics
// are needed, each thread's random writes land in a smaller part of memory, and every row receives
// its contributions in input order whatever the number of threads.
#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace detail {

/** Runs body(first, last) once per thread, on the thread's own contiguous range of vertices. */
template <class Body>
void forEachVertexRange(int num_vertices, const Body& body) {
#pragma omp parallel
  {
#ifdef _OPENMP
    const std::int64_t threads = omp_get_num_threads(), id = omp_get_thread_num();
#else
    const std::int64_t threads = 1, id = 0;
#endif
    body(static_cast<int>(num_vertices * id / threads),
         static_cast<int>(num_vertices * (id + 1) / threads));
  }
}

}  // namespace detail
}  // namespace pcl_ddg
