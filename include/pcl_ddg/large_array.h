#pragma once
/** \file
 * Arrays of a value or a row per point, filled right after they are made (a neighbour graph's
 * rows, the moments of a level of wider planes): on transparent huge pages.
 *
 * A fresh 4 KiB page costs a fault, and in a VM the fault goes through the hypervisor: 11-18 us
 * a page on a freshly booted 2-core VM, more than filling it. A block of at least one huge page
 * (2 MiB) is mapped from a huge page's boundary, advised for huge pages and populated in one
 * call; smaller ones come from the heap. Where the kernel gives no huge pages (THP "never"), the
 * one call populates 4 KiB pages. Where hugePagesAllowed() says no, every block is the heap's.
 */
#include <cstddef>
#include <memory>
#include <vector>

namespace pcl_ddg {
namespace detail {

/** The smallest block allocateLargeArray takes. */
constexpr std::size_t kLargeArrayBytes = std::size_t{2} << 20;

/** Whether this process asks for huge pages (large arrays here, the tools' heap in
 *  tools/common/huge_pages.h): not in a sanitizer build (whose checks do not see mapped blocks),
 *  not under valgrind, not with the environment variable PCL_DDG_HUGE_PAGES=0. Read once, at the
 *  first call, and the same for the rest of the process. */
bool hugePagesAllowed();

/** A block of bytes >= kLargeArrayBytes: mapped on huge pages and populated, or the heap's where
 *  hugePagesAllowed() says no; throws std::bad_alloc when the memory cannot be had. */
void* allocateLargeArray(std::size_t bytes);

/** Releases a block of allocateLargeArray(bytes). */
void releaseLargeArray(void* block, std::size_t bytes) noexcept;

/** std::allocator's interface over allocateLargeArray for blocks of at least kLargeArrayBytes. */
template <typename T>
struct LargeArrayAllocator {
  using value_type = T;

  LargeArrayAllocator() = default;
  template <typename U>
  LargeArrayAllocator(const LargeArrayAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n * sizeof(T) < kLargeArrayBytes) return std::allocator<T>().allocate(n);
    return static_cast<T*>(allocateLargeArray(n * sizeof(T)));
  }
  void deallocate(T* block, std::size_t n) noexcept {
    if (n * sizeof(T) < kLargeArrayBytes)
      std::allocator<T>().deallocate(block, n);
    else
      releaseLargeArray(block, n * sizeof(T));
  }
  template <typename U>
  bool operator==(const LargeArrayAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const LargeArrayAllocator<U>&) const noexcept {
    return false;
  }
};

/** A std::vector whose storage of at least kLargeArrayBytes is on huge pages. */
template <typename T>
using LargeArray = std::vector<T, LargeArrayAllocator<T>>;

}  // namespace detail
}  // namespace pcl_ddg
