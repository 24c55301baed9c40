#include "detail/populated_memory.h"

#include <sys/mman.h>

namespace pcl_ddg {
namespace detail {

void* mapPopulated(std::size_t bytes) {
  void* block = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (block == MAP_FAILED) return nullptr;
  // Advice before the pages exist: a range already populated in 4 kB pages stays so. Both calls
  // are hints: where the kernel refuses either, the pages come one fault at a time as before.
  madvise(block, bytes, MADV_HUGEPAGE);
#ifdef MADV_POPULATE_WRITE
  madvise(block, bytes, MADV_POPULATE_WRITE);
#endif
  return block;
}

void unmapPopulated(void* block, std::size_t bytes) {
  munmap(block, bytes);
}

}  // namespace detail
}  // namespace pcl_ddg
