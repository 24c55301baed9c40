// The allocator SparseCholesky installs into SuiteSparse: large blocks mapped and populated, small
// ones from malloc, each function accepting the others' blocks (and malloc's), and installed only
// over the C library's own functions.
#include <gtest/gtest.h>

#include <SuiteSparse_config.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "operators/cholmod_memory.h"
#include "pcl_ddg/operators/sparse_cholesky.h"

namespace pcl_ddg {
namespace test {
namespace {

constexpr std::size_t kSmall = 1000, kLarge = std::size_t{3} << 20;

void fill(void* block, std::size_t bytes) {
  auto* data = static_cast<unsigned char*>(block);
  for (std::size_t i = 0; i < bytes; ++i) data[i] = static_cast<unsigned char>(i * 7 + 1);
}

bool holdsFill(const void* block, std::size_t bytes) {
  const auto* data = static_cast<const unsigned char*>(block);
  for (std::size_t i = 0; i < bytes; ++i) {
    if (data[i] != static_cast<unsigned char>(i * 7 + 1)) return false;
  }
  return true;
}

TEST(CholmodMemory, ReallocKeepsTheContentsAcrossTheMappedSize) {
  void* block = detail::populatedMalloc(kSmall);
  ASSERT_NE(block, nullptr);
  fill(block, kSmall);
  block = detail::populatedRealloc(block, kLarge);  // malloc -> mapped
  ASSERT_NE(block, nullptr);
  EXPECT_TRUE(holdsFill(block, kSmall));
  fill(block, kLarge);
  block = detail::populatedRealloc(block, 2 * kLarge);  // mapped -> mapped
  ASSERT_NE(block, nullptr);
  EXPECT_TRUE(holdsFill(block, kLarge));
  block = detail::populatedRealloc(block, kSmall);  // mapped -> malloc
  ASSERT_NE(block, nullptr);
  EXPECT_TRUE(holdsFill(block, kSmall));
  detail::populatedFree(block);
}

TEST(CholmodMemory, CallocIsZeroAndFreeTakesEveryKindOfBlock) {
  for (const std::size_t count : {kSmall, kLarge}) {
    auto* zeros = static_cast<unsigned char*>(detail::populatedCalloc(count, 8));
    ASSERT_NE(zeros, nullptr);
    EXPECT_EQ(zeros[0], 0);
    EXPECT_EQ(zeros[8 * count - 1], 0);
    detail::populatedFree(zeros);
  }
  EXPECT_EQ(detail::populatedCalloc(SIZE_MAX / 2, 4), nullptr);  // count x size overflows
  detail::populatedFree(std::malloc(kLarge));                    // a block from before the switch
  detail::populatedFree(nullptr);
  void* kept = detail::populatedMalloc(kSmall);
  EXPECT_EQ(detail::populatedRealloc(kept, SIZE_MAX / 2), nullptr);  // and the block stays valid
  detail::populatedFree(kept);
}

TEST(CholmodMemory, SparseCholeskyInstallsItOverTheDefaults) {
  const SparseCholesky solver(CholeskyBackend::Cholmod);
  EXPECT_EQ(SuiteSparse_config.malloc_func, &detail::populatedMalloc);
  EXPECT_EQ(SuiteSparse_config.free_func, &detail::populatedFree);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
