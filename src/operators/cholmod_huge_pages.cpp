#include "cholmod_huge_pages.h"

#include <SuiteSparse_config.h>

#include <cstdint>
#include <cstdlib>
#include <mutex>

#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace pcl_ddg {
namespace detail {
namespace {

constexpr std::size_t kSmallestAdvisedBlock = std::size_t{4} << 20;

void adviseHugePages(void* block, std::size_t size) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (block == nullptr || size < kSmallestAdvisedBlock) return;
  static const std::uintptr_t page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto begin = reinterpret_cast<std::uintptr_t>(block);
  const std::uintptr_t first = (begin + page - 1) & ~(page - 1);
  const std::uintptr_t last = (begin + size) & ~(page - 1);
  // Advice only: if it is refused the block simply keeps ordinary pages.
  madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
  (void)block;
  (void)size;
#endif
}

void* advisedMalloc(std::size_t size) {
  void* block = std::malloc(size);
  adviseHugePages(block, size);
  return block;
}

void* advisedCalloc(std::size_t count, std::size_t size) {
  void* block = std::calloc(count, size);
  if (block != nullptr) adviseHugePages(block, count * size);  // no overflow: calloc succeeded
  return block;
}

void* advisedRealloc(void* old_block, std::size_t size) {
  void* block = std::realloc(old_block, size);
  adviseHugePages(block, size);
  return block;
}

}  // namespace

void adviseHugePagesForCholmod() {
  // SuiteSparse 7 hides its configuration behind accessors; there the default allocator stays.
#if SUITESPARSE_MAIN_VERSION < 7
  static std::once_flag once;
  std::call_once(once, [] {
    SuiteSparse_config_struct& config = SuiteSparse_config;
    if (config.malloc_func != &std::malloc || config.calloc_func != &std::calloc ||
        config.realloc_func != &std::realloc || config.free_func != &std::free) {
      return;
    }
    config.malloc_func = &advisedMalloc;
    config.calloc_func = &advisedCalloc;
    config.realloc_func = &advisedRealloc;
  });
#endif
}

}  // namespace detail
}  // namespace pcl_ddg
