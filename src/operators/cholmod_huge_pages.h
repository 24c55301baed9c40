#pragma once
// Transparent huge pages for CHOLMOD's large blocks (the factor, its workspaces, the solve
// buffers). Where page faults are expensive, as in virtual machines, the first factorisation of a
// million-vertex system spent more time faulting in its 0.8 GB factor than computing it: with
// 2 MiB pages the first implicit smoothing step of the 1.15M-vertex benchmark torus went from
// 10.7 s to 6.6 s and every later step from 4.6 s to 4.1 s (two-core VM, bench_smoothing).

namespace pcl_ddg {
namespace detail {

/** Once per process: has SuiteSparse allocate through malloc / calloc / realloc followed by
 *  madvise(MADV_HUGEPAGE) on blocks of 4 MiB and more. Only advice (ignored where huge pages are
 *  disabled), and only if SuiteSparse still uses the C library's allocator: a program that
 *  installed its own keeps it. */
void adviseHugePagesForCholmod();

}  // namespace detail
}  // namespace pcl_ddg
