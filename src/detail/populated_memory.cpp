#include "detail/populated_memory.h"

#include <sys/mman.h>

#include <new>

#include "pcl_ddg/large_array.h"

// Linux 5.14's value; older C library headers do not name it, and older kernels refuse it (EINVAL).
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

namespace pcl_ddg {
namespace detail {
namespace {

void* mapAnonymous(std::size_t bytes, int extra_flags) {
  void* block = mmap(nullptr, bytes, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | extra_flags, -1, 0);
  return block == MAP_FAILED ? nullptr : block;
}

}  // namespace

void* mapPopulated(std::size_t bytes, PageSize pages) {
  if (pages == PageSize::kSmall) return mapAnonymous(bytes, MAP_POPULATE);
  void* block = mapAnonymous(bytes, 0);
  if (block == nullptr) return nullptr;
  // The advice must come before the pages exist: a range populated in 4 KiB pages stays so
  // (until khugepaged merges it, if ever). Where the kernel gives no huge pages, the advice is
  // without effect and the populate call makes small ones.
  madvise(block, bytes, MADV_HUGEPAGE);
  if (madvise(block, bytes, MADV_POPULATE_WRITE) == 0) return block;
  munmap(block, bytes);
  return mapAnonymous(bytes, MAP_POPULATE);
}

void unmapPopulated(void* block, std::size_t bytes) {
  munmap(block, bytes);
}

void* allocateLargeArray(std::size_t bytes) {
  void* block = mapPopulated(bytes, PageSize::kHuge);
  if (block == nullptr) throw std::bad_alloc();
  return block;
}

void releaseLargeArray(void* block, std::size_t bytes) noexcept {
  unmapPopulated(block, bytes);
}

}  // namespace detail
}  // namespace pcl_ddg
