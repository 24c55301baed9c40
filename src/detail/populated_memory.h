#pragma once
// Large anonymous blocks whose pages are made in one call, on huge pages where the kernel has them.
//
// A fresh page costs a fault, and in a VM the fault and every TLB miss on a 4 kB page go through
// the hypervisor: reading a 92 MB file into memory populated in 4 kB pages took 120-170 ms on a
// freshly booted 2-core VM (23,556 faults counted by getrusage), into memory advised for 2 MB pages
// 13 ms (51 faults). The kernel gives huge pages only to ranges advised so (transparent huge pages
// in "madvise" mode, Debian's default) and falls back to 4 kB pages when it has none.

#include <cstddef>

namespace pcl_ddg {
namespace detail {

/** A private anonymous mapping of `bytes` (> 0), zero-filled, advised for transparent huge pages
 *  and populated before it returns (MADV_POPULATE_WRITE; on kernels before 5.14 the pages are
 *  faulted in on first touch instead). nullptr if the memory cannot be had. Release it with
 *  unmapPopulated(block, bytes). */
void* mapPopulated(std::size_t bytes);

/** Releases a block of mapPopulated(bytes). */
void unmapPopulated(void* block, std::size_t bytes);

}  // namespace detail
}  // namespace pcl_ddg
