// COPC (pcl_ddg/io/copc.h) on PDAL's COPC test file (1,065 points in 65 nodes, CATALOG.md): the
// octree read from the hierarchy, every node's points within its cube and all of them the
// file's; a box read from only the nodes that meet it, to exactly the file's points inside it;
// hierarchy pages followed, and lying ones refused. The positions are compared with those of
// readMeshFile of the whole file (itself checked against the uncompressed twin, test_laz_io).
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/copc.h"
#include "pcl_ddg/io/mesh_io.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

using Point = std::array<double, 3>;

std::string copcFile() {
  return sharedData("las/laz/1.2-with-color.copc.laz");
}

std::vector<Point> sortedPoints(const Eigen::Matrix3Xd& positions) {
  std::vector<Point> points;
  for (Eigen::Index i = 0; i < positions.cols(); ++i)
    points.push_back({positions(0, i), positions(1, i), positions(2, i)});
  std::sort(points.begin(), points.end());
  return points;
}

template <typename T>
T at(const std::string& b, std::size_t offset) {
  T v;
  std::memcpy(&v, b.data() + offset, sizeof v);
  return v;
}
template <typename T>
void put(std::string& b, std::size_t offset, T v) {
  std::memcpy(&b[offset], &v, sizeof v);
}

// The info VLR's payload by the COPC specification: the first VLR, after the 375-byte header.
constexpr std::size_t kInfo = 375 + 54;

TEST(Copc, TheOctreeHoldsEveryPointOnceEachWithinItsNode) {
  const CopcInfo info = readCopcInfo(copcFile());
  EXPECT_EQ(info.point_count, 1065u);
  EXPECT_EQ(info.hierarchy_pages, 1u);
  ASSERT_EQ(info.nodes.size(), 65u);
  EXPECT_TRUE(info.nodes.front().key == (CopcKey{0, 0, 0, 0}));
  const MeshFile whole = readMeshFile(copcFile());
  std::vector<CopcKey> keys;
  Eigen::Matrix3Xd all(3, 0);
  for (const CopcNode& node : info.nodes) {
    EXPECT_LE(node.key.depth, 3);
    const CopcPoints points = readCopcNodes(copcFile(), {node.key});
    ASSERT_EQ(points.file.positions.cols(), node.points) << node.key.depth;
    // Within the node's cube, give or take the coordinates' rounding to the scale (0.01).
    Eigen::AlignedBox3d cube = info.bounds(node.key);
    cube.extend(cube.min() - Eigen::Vector3d::Constant(0.01));
    cube.extend(cube.max() + Eigen::Vector3d::Constant(0.01));
    for (Eigen::Index i = 0; i < points.file.positions.cols(); ++i)
      EXPECT_TRUE(cube.contains(points.file.positions.col(i)));
    all.conservativeResize(3, all.cols() + points.file.positions.cols());
    all.rightCols(points.file.positions.cols()) = points.file.positions;
    keys.push_back(node.key);
  }
  EXPECT_EQ(sortedPoints(all), sortedPoints(whole.positions));
  // All the nodes at once, in the hierarchy's order: the file's records in the file's order
  // (its chunks are stored in another order, so this is not the whole file read again).
  const CopcPoints together = readCopcNodes(copcFile(), keys);
  EXPECT_TRUE(together.file.positions == all);
  EXPECT_EQ(together.file.mesh.cloud.fields.size(), whole.mesh.cloud.fields.size());
  EXPECT_THROW(readCopcNodes(copcFile(), {{4, 0, 0, 0}}), pcl::BadArgumentException);
}

TEST(Copc, ABoxReadsOnlyTheNodesMeetingItAndGivesExactlyThePointsInside) {
  const CopcInfo info = readCopcInfo(copcFile());
  const MeshFile whole = readMeshFile(copcFile());
  Eigen::AlignedBox3d data;
  for (Eigen::Index i = 0; i < whole.positions.cols(); ++i) data.extend(whole.positions.col(i));
  // The points' south-west quarter in plan, every height; then a box about their middle.
  const Eigen::Vector3d up(0, 0, 1e9), side = data.sizes();
  const Eigen::AlignedBox3d quarter(data.min() - up, data.center() + up);
  const Eigen::AlignedBox3d small(
      data.center() - 0.2 * side - up,
      data.center() + Eigen::Vector3d(0.3, 0.1, 0).cwiseProduct(side) + up);
  for (const Eigen::AlignedBox3d& box : {quarter, small}) {
    for (const int depth : {-1, 1}) {
      const CopcPoints read = readCopcBox(copcFile(), box, depth);
      // Expected: every node of those levels read alone, its points in the box kept.
      std::vector<Point> expected;
      std::uint64_t node_bytes = 0;
      for (const CopcNode& node : info.nodes) {
        if (depth >= 0 && node.key.depth > depth) continue;
        const CopcPoints points = readCopcNodes(copcFile(), {node.key});
        for (Eigen::Index i = 0; i < points.file.positions.cols(); ++i)
          if (box.contains(points.file.positions.col(i)))
            expected.push_back({points.file.positions(0, i), points.file.positions(1, i),
                                points.file.positions(2, i)});
        // What is read (docs/las.md): the nodes whose cubes, widened by a scale step, meet it.
        Eigen::AlignedBox3d cube = info.bounds(node.key);
        cube.min() -= info.scale;
        cube.max() += info.scale;
        if (cube.intersects(box)) node_bytes += node.bytes;
      }
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(sortedPoints(read.file.positions), expected) << depth;
      // Every level: the points of the whole file within the box, none left out.
      if (depth < 0) {
        std::vector<Point> inside;
        for (const Point& p : sortedPoints(whole.positions))
          if (box.contains(Eigen::Vector3d(p[0], p[1], p[2]))) inside.push_back(p);
        EXPECT_EQ(expected, inside);
        EXPECT_GT(inside.size(), 50u);
        EXPECT_LT(inside.size(), 1065u);
      }
      // Read: the header and VLRs (twice: the octree, then the points), the hierarchy, the
      // chosen chunks; less than the file.
      const std::string bytes = readBytes(copcFile());
      const std::uint64_t point_offset = at<std::uint32_t>(bytes, 96);
      EXPECT_EQ(read.bytes_read, 2 * point_offset + 65 * 32 + node_bytes);
      EXPECT_LT(read.bytes_read, bytes.size());
    }
  }
  // A box around one point gives that point, though a point may lie up to half a scale step
  // outside its node's cube (one in the file lies 1.1e-13 below node 3-0-0-0's).
  for (Eigen::Index i = 0; i < whole.positions.cols(); ++i) {
    const Eigen::Vector3d p = whole.positions.col(i);
    const CopcPoints one = readCopcBox(copcFile(), Eigen::AlignedBox3d(p, p));
    ASSERT_GE(one.file.positions.cols(), 1) << i;
    for (Eigen::Index j = 0; j < one.file.positions.cols(); ++j)
      EXPECT_TRUE(one.file.positions.col(j) == p) << i;
  }
}

// The shared file's hierarchy is one page: moved here into two, the depth-3 entries in a child
// page appended to the file and named from the root page, as large files are laid out.
std::string twoPageCopy(std::uint64_t* child_offset) {
  std::string b = readBytes(copcFile());
  const auto root = at<std::uint64_t>(b, kInfo + 40);
  const auto size = at<std::uint64_t>(b, kInfo + 48);
  std::string kept, moved;
  for (std::uint64_t e = root; e < root + size; e += 32)
    (at<std::int32_t>(b, e) == 3 ? moved : kept) += b.substr(e, 32);
  *child_offset = b.size();
  std::string pointer(32, '\0');
  put<std::int32_t>(pointer, 0, 1);  // the child page's subtree: key 1-0-0-0
  put<std::uint64_t>(pointer, 16, b.size());
  put<std::int32_t>(pointer, 24, static_cast<std::int32_t>(moved.size()));
  put<std::int32_t>(pointer, 28, -1);
  kept += pointer;
  b.replace(root, kept.size(), kept);
  put<std::uint64_t>(b, kInfo + 48, kept.size());
  return b + moved;
}

TEST(Copc, ChildPagesAreFollowedAndLyingHierarchiesRefused) {
  const std::string folder = scratchFolder("copc_pages");
  std::uint64_t child = 0;
  const std::string two = twoPageCopy(&child);
  writeText(folder + "/two.copc.laz", two);
  const CopcInfo info = readCopcInfo(folder + "/two.copc.laz");
  EXPECT_EQ(info.hierarchy_pages, 2u);
  EXPECT_EQ(info.nodes.size(), 65u);
  std::vector<CopcKey> keys;
  for (const CopcNode& node : info.nodes) keys.push_back(node.key);
  EXPECT_EQ(sortedPoints(readCopcNodes(folder + "/two.copc.laz", keys).file.positions),
            sortedPoints(readMeshFile(copcFile()).positions));

  const auto refused = [&](std::string bytes, const std::string& why) {
    writeText(folder + "/bad.copc.laz", bytes);
    try {
      readCopcInfo(folder + "/bad.copc.laz");
      ADD_FAILURE() << "accepted: " << why;
    } catch (const FileFormatException& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  const auto root = at<std::uint64_t>(two, kInfo + 40);
  const auto root_size = at<std::uint64_t>(two, kInfo + 48);
  const std::size_t pointer = root + root_size - 32;
  std::string cycle = two;  // the child page names itself
  cycle.replace(child, 32, cycle.substr(pointer, 32));
  refused(cycle, "named twice");
  std::string beyond = two;  // the child page past the end
  put<std::uint64_t>(beyond, pointer + 16, two.size() - 64);
  refused(beyond, "not whole entries within the file");
  std::string lie = two;  // a node claims one point more
  put<std::int32_t>(lie, root + 28, at<std::int32_t>(lie, root + 28) + 1);
  refused(lie, "hold 1066 points, the header 1065");
  std::string outside = two;  // a key beyond its depth's cubes
  put<std::int32_t>(outside, root + 4, 1);
  refused(outside, "is not a node of the octree");
  std::string chunk = two;  // a node's chunk past the end
  put<std::uint64_t>(chunk, root + 16, two.size());
  refused(chunk, "chunk is not within the file");
  std::string twice = two;  // two entries of one key
  twice.replace(root + 32, 16, twice.substr(root, 16));
  refused(twice, "is listed twice");
  std::string shared = two;  // nodes 2 and 3 share node 2's chunk (the header counts them)
  put<std::uint64_t>(shared, root + 64 + 16, at<std::uint64_t>(shared, root + 32 + 16));
  put<std::int32_t>(shared, root + 64 + 24, at<std::int32_t>(shared, root + 32 + 24));
  const std::int32_t moved =
      at<std::int32_t>(shared, root + 32 + 28) - at<std::int32_t>(shared, root + 64 + 28);
  put<std::int32_t>(shared, root + 64 + 28, at<std::int32_t>(shared, root + 32 + 28));
  put<std::uint64_t>(shared, 247, 1065 + static_cast<std::int64_t>(moved));
  refused(shared, "overlaps another chunk");
  std::string overlapping = two;  // every chunk the whole file
  for (std::size_t e = root; e < pointer; e += 32) {
    put<std::uint64_t>(overlapping, e + 16, 0);
    put<std::int32_t>(overlapping, e + 24, static_cast<std::int32_t>(child));
  }
  refused(overlapping, "add up to more than the file");
  std::string truncated = two.substr(0, child + 16);
  refused(truncated, "not whole entries within the file");
}

TEST(Copc, OtherFilesAreNotCopc) {
  EXPECT_TRUE(isCopcFile(copcFile()));
  for (const char* name :
       {"las/laz/autzen_trim.laz", "las/simple.laz", "las/1.2-with-color.las", "las/test1_4.las"}) {
    EXPECT_FALSE(isCopcFile(sharedData(name))) << name;
    EXPECT_THROW(readCopcInfo(sharedData(name)), FileFormatException) << name;
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
