#pragma once
// CHOLMOD's large blocks with their pages populated in one call.
//
// The supernodal factor of a 1M-vertex mesh is about a gigabyte, allocated fresh and first
// touched by CHOLMOD's memset. Faulted in one page at a time, that first touch costs microseconds
// a page in a VM (clear_page was 18% of the first implicit step); populated in one call
// (detail/populated_memory.h) it costs about half. In 4 KiB pages: huge pages made the first step
// slower on a VM whose freed memory goes back to the host (docs/design/implicit-solver.md).

#include <cstddef>

namespace pcl_ddg {
namespace detail {

/** Routes CHOLMOD's allocations of 1 MiB or more through populated anonymous mappings, once per
 *  process. SuiteSparse keeps its allocator in one global (SuiteSparse_config), so this is done
 *  only while that global still holds the C library's functions: a program that installed its
 *  own allocator keeps it. Blocks allocated before the switch are still freed by free(). */
void populateCholmodAllocations();

/** The functions installed: blocks below 1 MiB from malloc, larger ones mapped and populated.
 *  Each accepts what the others returned, and blocks from malloc itself. */
void* populatedMalloc(std::size_t bytes);
void* populatedCalloc(std::size_t count, std::size_t size);
void* populatedRealloc(void* block, std::size_t bytes);
void populatedFree(void* block);

}  // namespace detail
}  // namespace pcl_ddg
