#include "detail/populated_memory.h"

#include <sys/mman.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

#include "pcl_ddg/large_array.h"

// Linux 5.14's value; older C library headers do not name it, and older kernels refuse it (EINVAL).
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

namespace pcl_ddg {
namespace detail {
namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
constexpr bool kSanitizerBuild = true;
#else
constexpr bool kSanitizerBuild = false;
#endif
#else
constexpr bool kSanitizerBuild = false;
#endif

constexpr std::size_t kHugePage = std::size_t{2} << 20;

void* mapAnonymous(std::size_t bytes, int extra_flags) {
  void* block = mmap(nullptr, bytes, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | extra_flags, -1, 0);
  return block == MAP_FAILED ? nullptr : block;
}

/** A mapping of bytes that starts on a huge page's boundary: the kernel backs only whole aligned
 *  2 MiB spans with a huge page, and mmap aligns to 4 KiB. Mapped a huge page longer, the parts
 *  before the boundary and after the block unmapped. */
void* mapAligned(std::size_t bytes) {
  const std::size_t length = (bytes + 4095) / 4096 * 4096;
  auto* mapped = static_cast<char*>(mapAnonymous(length + kHugePage, 0));
  if (mapped == nullptr) return nullptr;
  const auto address = reinterpret_cast<std::uintptr_t>(mapped);
  char* block = mapped + ((kHugePage - address % kHugePage) % kHugePage);
  if (block != mapped) munmap(mapped, static_cast<std::size_t>(block - mapped));
  const std::size_t tail = static_cast<std::size_t>(mapped + length + kHugePage - (block + length));
  if (tail > 0) munmap(block + length, tail);
  return block;
}

}  // namespace

void* mapPopulated(std::size_t bytes, PageSize pages) {
  if (pages == PageSize::kSmall) return mapAnonymous(bytes, MAP_POPULATE);
  void* block = mapAligned(bytes);
  if (block == nullptr) return nullptr;
  // The advice must come before the pages exist: a range populated in 4 KiB pages stays so
  // (until khugepaged merges it, if ever). Where the kernel gives no huge pages, the advice is
  // without effect and the populate call makes small ones.
  madvise(block, bytes, MADV_HUGEPAGE);
  if (madvise(block, bytes, MADV_POPULATE_WRITE) == 0) return block;
  const int error = errno;
  munmap(block, bytes);
  // A kernel before 5.14 does not know the call: MAP_POPULATE's small pages. Out of memory is
  // out of memory.
  if (error == EINVAL) return mapAnonymous(bytes, MAP_POPULATE);
  errno = error;  // what a caller reports
  return nullptr;
}

void unmapPopulated(void* block, std::size_t bytes) {
  munmap(block, bytes);
}

bool hugePagesAllowed() {
  static const bool allowed = [] {
    const char* wanted = std::getenv("PCL_DDG_HUGE_PAGES");
    const char* preloaded = std::getenv("LD_PRELOAD");
    return !kSanitizerBuild && !(wanted != nullptr && std::strcmp(wanted, "0") == 0) &&
           !(preloaded != nullptr && std::strstr(preloaded, "vgpreload") != nullptr);
  }();
  return allowed;
}

void* allocateLargeArray(std::size_t bytes) {
  void* block = hugePagesAllowed() ? mapPopulated(bytes, PageSize::kHuge) : std::malloc(bytes);
  if (block == nullptr) throw std::bad_alloc();
  return block;
}

void releaseLargeArray(void* block, std::size_t bytes) noexcept {
  if (hugePagesAllowed())
    unmapPopulated(block, bytes);
  else
    std::free(block);
}

}  // namespace detail
}  // namespace pcl_ddg
