// The allocator tuneCholmodForLargeSystems installs into SuiteSparse: large blocks mapped and
// populated, small ones from malloc, each function accepting the others' blocks (and malloc's), and
// installed only over the C library's own functions.
#include <gtest/gtest.h>

#include <SuiteSparse_config.h>

#include <Eigen/SparseCore>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "operators/cholmod_memory.h"
#include "pcl_ddg/operators/sparse_cholesky.h"

namespace pcl_ddg {
namespace test {
namespace {

constexpr std::size_t kSmall = 1000, kLarge = std::size_t{3} << 20;

// Constructed before the allocator's table of mapped blocks exists, so destroyed after it would
// be: its factor's blocks are freed during exit (a crash or a sanitizer report if the table were
// gone by then).
SparseCholesky solver_in_a_static(CholeskyBackend::Cholmod);

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

// Process-wide state is the host program's: a solver leaves it alone until asked to tune it.
TEST(CholmodMemory, InstalledOverTheDefaultsOnlyWhenTuningIsAskedFor) {
  SparseCholesky solver(CholeskyBackend::Cholmod);
  solver.compute(Eigen::SparseMatrix<double>(Eigen::MatrixXd::Identity(3, 3).sparseView()));
  if (!cholmodTunedForLargeSystems()) {
    EXPECT_EQ(SuiteSparse_config.malloc_func, &std::malloc);
    EXPECT_EQ(SuiteSparse_config.free_func, &std::free);
  }
  tuneCholmodForLargeSystems();
  EXPECT_TRUE(cholmodTunedForLargeSystems());
  EXPECT_EQ(SuiteSparse_config.malloc_func, &detail::populatedMalloc);
  EXPECT_EQ(SuiteSparse_config.free_func, &detail::populatedFree);
}

TEST(CholmodMemory, AFactorInAStaticObjectIsFreedAtExit) {
  tuneCholmodForLargeSystems();
  // The 5-point Laplacian of a 300 x 300 grid plus the identity: a factor of several MiB.
  const int side = 300, n = side * side;
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 5.0);
    if (i % side + 1 < side) entries.emplace_back(i, i + 1, -1.0);
    if (i + side < n) entries.emplace_back(i, i + side, -1.0);
  }
  Eigen::SparseMatrix<double> upper(n, n);
  upper.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<double> matrix = upper.selfadjointView<Eigen::Upper>();
  solver_in_a_static.compute(matrix);
  const Eigen::VectorXd x = solver_in_a_static.solve(Eigen::MatrixXd::Ones(n, 1));
  EXPECT_LT((matrix * x - Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
