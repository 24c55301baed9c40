#pragma once
// Union-find with path halving and union by size, plain and with a parity per element; internal to
// the library (the mesh layer, orientation). Both are near-linear on any input (no chains, whatever
// the element order).
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace pcl_ddg {
namespace detail {

class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(n), size_(n, 1) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  /** Returns true if a and b were in different sets. */
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return true;
  }

 private:
  std::vector<int> parent_;
  std::vector<int> size_;
};

/**
 * Union-find whose elements also carry a parity (one bit) relative to their set's root: used to
 * orient triangles, where the parity says "flipped relative to the root". Path compression keeps
 * the parities by XOR-ing them along the path; union by size keeps trees shallow.
 */
class ParityDisjointSets {
 public:
  explicit ParityDisjointSets(int n) : parent_(n), size_(n, 1), parity_(n, 0) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }

  struct Root {
    int root;
    char parity;  ///< of the element relative to root
  };

  Root find(int x) {
    // First pass: the root and the element's parity; second: point the path at the root.
    int root = x;
    char parity = 0;
    while (parent_[root] != root) {
      parity ^= parity_[root];
      root = parent_[root];
      ++steps_;
    }
    char remaining = parity;  // parity of the current path element relative to the root
    while (parent_[x] != root && x != root) {
      const int next = parent_[x];
      const char own = parity_[x];
      parent_[x] = root;
      parity_[x] = remaining;
      remaining ^= own;
      x = next;
    }
    return {root, parity};
  }

  /** Requires parity(a) ^ parity(b) == relative. Returns false if that contradicts what is known
   *  already (same set, other parity). */
  bool unite(int a, int b, char relative) {
    const Root ra = find(a), rb = find(b);
    if (ra.root == rb.root) return (ra.parity ^ rb.parity) == relative;
    int big = ra.root, small = rb.root;
    if (size_[big] < size_[small]) std::swap(big, small);
    parent_[small] = big;
    size_[big] += size_[small];
    parity_[small] = ra.parity ^ rb.parity ^ relative;
    return true;
  }

  /** Parent links followed by find so far (the linear-time test counts them). */
  std::int64_t steps() const { return steps_; }

 private:
  std::vector<int> parent_;
  std::vector<int> size_;
  std::vector<char> parity_;
  std::int64_t steps_ = 0;
};

}  // namespace detail
}  // namespace pcl_ddg
