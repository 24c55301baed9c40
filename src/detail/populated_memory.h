#pragma once
// Large anonymous blocks whose pages are made in one call, before they are written.
//
// A fresh page costs a fault, and in a VM the fault goes through the hypervisor: on a freshly
// booted 2-core VM a first touch of a 4 KiB page cost 11-18 us. Reading the 92 MiB bench OFF
// into memory populated in 4 KiB pages took 120-170 ms there (23,556 faults counted by
// getrusage), into memory advised for 2 MiB pages 13 ms (51 faults).

#include <cstddef>

namespace pcl_ddg {
namespace detail {

/** The pages a block is asked for with. */
enum class PageSize {
  kSmall,  ///< 4 KiB pages
  /** Transparent huge pages (2 MiB) where the kernel gives them to ranges advised so (THP in
   *  "madvise" or "always" mode); 4 KiB pages where it does not. */
  kHuge,
};

/** A private anonymous mapping of `bytes` (> 0), zero-filled, its pages populated before it
 *  returns: MAP_POPULATE for small pages; for huge pages a mapping from a huge page's boundary,
 *  the advice first, then MADV_POPULATE_WRITE, or MAP_POPULATE's small pages on a kernel without
 *  it (before 5.14). nullptr, errno set, if the memory cannot be had. Release it with
 *  unmapPopulated(block, bytes). */
void* mapPopulated(std::size_t bytes, PageSize pages);

/** Releases a block of mapPopulated(bytes, ...). */
void unmapPopulated(void* block, std::size_t bytes);

}  // namespace detail
}  // namespace pcl_ddg
