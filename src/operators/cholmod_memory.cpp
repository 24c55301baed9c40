#include "cholmod_memory.h"

#include <SuiteSparse_config.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <unordered_map>

#include "detail/populated_memory.h"

namespace pcl_ddg {
namespace detail {
namespace {

constexpr std::size_t kPopulatedBytes = std::size_t{1} << 20;

// The mapped blocks and their lengths, which munmap needs and free() must never see. Never
// destroyed: a solver in a static object frees its factor after function-local statics are gone.
std::mutex mapped_mutex;
std::unordered_map<void*, std::size_t>& mappedBlocks() {
  static auto* const blocks = new std::unordered_map<void*, std::size_t>();
  return *blocks;
}

// The length of a mapped block, or 0 for one from malloc.
std::size_t mappedLength(void* block) {
  const std::lock_guard<std::mutex> lock(mapped_mutex);
  const auto found = mappedBlocks().find(block);
  return found == mappedBlocks().end() ? 0 : found->second;
}

}  // namespace

void* populatedMalloc(std::size_t bytes) {
  if (bytes < kPopulatedBytes) return std::malloc(bytes);
  void* block = mapPopulated(bytes, PageSize::kSmall);
  if (block == nullptr) return nullptr;
  try {
    const std::lock_guard<std::mutex> lock(mapped_mutex);
    mappedBlocks().emplace(block, bytes);
  } catch (...) {
    unmapPopulated(block, bytes);
    return nullptr;
  }
  return block;
}

void populatedFree(void* block) {
  if (block == nullptr) return;
  {
    const std::lock_guard<std::mutex> lock(mapped_mutex);
    const auto found = mappedBlocks().find(block);
    if (found != mappedBlocks().end()) {
      unmapPopulated(block, found->second);
      mappedBlocks().erase(found);
      return;
    }
  }
  std::free(block);
}

void* populatedCalloc(std::size_t count, std::size_t size) {
  if (size != 0 && count > SIZE_MAX / size) return nullptr;
  // Anonymous mappings are zero already.
  return count * size < kPopulatedBytes ? std::calloc(count, size) : populatedMalloc(count * size);
}

void* populatedRealloc(void* block, std::size_t bytes) {
  if (block == nullptr) return populatedMalloc(bytes);
  const std::size_t mapped = mappedLength(block);
  if (mapped == 0 && bytes < kPopulatedBytes) return std::realloc(block, bytes);
  void* moved = populatedMalloc(bytes);
  if (moved == nullptr) return nullptr;  // the old block stays valid, as realloc promises
  const std::size_t old_bytes = mapped != 0 ? mapped : malloc_usable_size(block);
  std::memcpy(moved, block, old_bytes < bytes ? old_bytes : bytes);
  populatedFree(block);
  return moved;
}

void populateCholmodAllocations() {
  static std::once_flag once;
  std::call_once(once, [] {
    SuiteSparse_config_struct& config = SuiteSparse_config;
    if (config.malloc_func != &std::malloc || config.calloc_func != &std::calloc ||
        config.realloc_func != &std::realloc || config.free_func != &std::free) {
      return;
    }
    config.malloc_func = populatedMalloc;
    config.calloc_func = populatedCalloc;
    config.realloc_func = populatedRealloc;
    config.free_func = populatedFree;
  });
}

}  // namespace detail
}  // namespace pcl_ddg
