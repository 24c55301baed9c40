// The text loaders parse numbers with std::from_chars in one pass over the file. They must read
// exactly what a reference parser reads: the C library's strtod on numbers written with %.17g (the
// shortest text that round-trips every double), and PCL's own PLY and PCD readers on every shared
// file, an independent implementation of those formats.
#include <gtest/gtest.h>

#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/mesh_io.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

std::uint64_t bitsOf(double value) {
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// Doubles of every magnitude a coordinate can have (within float range, which the loaders
// require), both signs, subnormal doubles, signed zeros, and numbers next to powers of ten.
std::vector<std::string> randomCoordinatesAsText(std::size_t count) {
  std::mt19937_64 random(2026);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  std::uniform_int_distribution<int> exponent(-320, 37);
  std::vector<std::string> text = {
      "0",   "-0",   "4.9406564584124654e-324", "1e-310",  "1e+38",   "-3.4028234663852886e+38",
      "0.1", "1e-5", "100000.12345678901",      "1.5e+00", "-2.5E-3", "7"};
  char buffer[40];
  while (text.size() < count) {
    double value = mantissa(random) * std::pow(10.0, exponent(random));
    if (random() % 2) value = -value;
    if (random() % 5 == 0) value = std::nextafter(std::pow(10.0, exponent(random) / 10), 0.0);
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    text.emplace_back(buffer);
  }
  return text;
}

// Writes the numbers as vertex coordinates (three per vertex) in a format's text form, loads the
// file and checks every coordinate against strtod on the same text, bit for bit.
void expectExactCoordinates(
    const std::string& path,
    const std::function<std::string(const std::vector<std::string>&, std::size_t)>& write_file) {
  SCOPED_TRACE(path);
  const std::vector<std::string> text = randomCoordinatesAsText(3 * 2000);
  const std::size_t vertices = text.size() / 3;
  std::ofstream(path) << write_file(text, vertices);
  const MeshFile file = readMeshFile(path);
  ASSERT_EQ(static_cast<std::size_t>(file.positions.cols()), vertices);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const double expected = std::strtod(text[i].c_str(), nullptr);
    const double actual =
        file.positions(static_cast<Eigen::Index>(i % 3), static_cast<Eigen::Index>(i / 3));
    ASSERT_EQ(bitsOf(actual), bitsOf(expected)) << "'" << text[i] << "' read as " << actual;
  }
}

std::string vertexLines(const std::vector<std::string>& text, const char* prefix) {
  std::string lines;
  for (std::size_t i = 0; i < text.size(); i += 3) {
    lines += prefix + text[i] + " " + text[i + 1] + " " + text[i + 2] + "\n";
  }
  return lines;
}

TEST(NumberParsing, SeventeenDigitDoublesAreReadExactlyInEveryTextFormat) {
  const std::string dir = scratchFolder("number_parsing");
  expectExactCoordinates(dir + "/numbers.off", [](const auto& text, std::size_t n) {
    return "OFF\n" + std::to_string(n) + " 1 0\n" + vertexLines(text, "") + "3 0 1 2\n";
  });
  expectExactCoordinates(dir + "/numbers.obj", [](const auto& text, std::size_t) {
    return vertexLines(text, "v ") + "f 1 2 3\n";
  });
  expectExactCoordinates(dir + "/numbers.ply", [](const auto& text, std::size_t n) {
    return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
           "\nproperty double x\nproperty double y\nproperty double z\nelement face 1\n"
           "property list uchar int vertex_indices\nend_header\n" +
           vertexLines(text, "") + "3 0 1 2\n";
  });
  expectExactCoordinates(dir + "/numbers.pcd", [](const auto& text, std::size_t n) {
    const std::string count = std::to_string(n);
    return "VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + count +
           "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + count + "\nDATA ascii\n" +
           vertexLines(text, "");
  });
  expectExactCoordinates(dir + "/numbers.vtk", [](const auto& text, std::size_t n) {
    return "# vtk DataFile Version 3.0\nnumbers\nASCII\nDATASET POLYDATA\nPOINTS " +
           std::to_string(n) + " double\n" + vertexLines(text, "") + "POLYGONS 1 4\n3 0 1 2\n";
  });
}

// A number with anything after it is not a number: "1.5x", "2e", "1.5.2", "1e5e", "nanx" and
// "inf0" are each refused with the text named, never read as their prefix; the spellings strtod
// alone knows ("-nan", "+inf", "infinity") are read.
TEST(NumberParsing, ANumberFollowedByJunkIsRefusedNotReadAsItsPrefix) {
  const std::string dir = scratchFolder("number_junk");
  const auto off = [&](const std::string& x) {
    const std::string path = dir + "/junk.off";
    std::ofstream(path) << "OFF\n3 1 0\n" << x << " 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    return path;
  };
  for (const char* junk : {"1.5x", "2e", "1.5.2", "1e5e", "nanx", "inf0"}) {
    try {
      readMeshFile(off(junk));
      ADD_FAILURE() << "'" << junk << "' was read as a number";
    } catch (const FileFormatException& e) {
      EXPECT_NE(std::string(e.what()).find(junk), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(std::isnan(readMeshFile(off("-nan")).positions(0, 0)));
  EXPECT_EQ(readMeshFile(off("+inf")).positions(0, 0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(readMeshFile(off("infinity")).positions(0, 0), std::numeric_limits<double>::infinity());
}

// PCL's readers give float x y z; ours give the file's exact values, which cast to float must be
// the same floats (the shared files hold at most 9 significant digits, so text -> double -> float
// cannot round twice differently from text -> float).
void expectSameFloatsAsPCL(const std::string& path, const pcl::PCLPointCloud2& pcl_cloud) {
  SCOPED_TRACE(path);
  pcl::PointCloud<pcl::PointXYZ> reference;
  pcl::fromPCLPointCloud2(pcl_cloud, reference);
  const MeshFile file = readMeshFile(path);
  ASSERT_EQ(static_cast<Eigen::Index>(reference.size()), file.positions.cols());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Eigen::Vector3f ours = file.positions.col(static_cast<Eigen::Index>(i)).cast<float>();
    for (int d = 0; d < 3; ++d) {
      if (std::isnan(reference[i].data[d])) {
        ASSERT_TRUE(std::isnan(ours[d])) << "point " << i;
      } else {
        ASSERT_EQ(ours[d], reference[i].data[d]) << "point " << i << " axis " << d;
      }
    }
  }
}

TEST(NumberParsing, EverySharedPlyAndPcdFileReadsAsPCLReadsIt) {
  const char* ply_files[] = {"meshes/bun045_rangegrid_tri.ply",
                             "meshes/bun_zipper.ply",
                             "meshes/bun_zipper_res3.ply",
                             "meshes/bun_zipper_res4.ply",
                             "meshes/horse.ply",
                             "meshes/igea.ply",
                             "range/bun000.ply"};
  for (const char* name : ply_files) {
    pcl::PolygonMesh mesh;
    ASSERT_EQ(pcl::io::loadPLYFile(sharedData(name), mesh), 0) << name;
    expectSameFloatsAsPCL(sharedData(name), mesh.cloud);
  }
  const char* pcd_files[] = {"clouds/bun0.pcd",
                             "clouds/milk.pcd",
                             "clouds/office1.pcd",
                             "clouds/rs1.pcd",
                             "clouds/table_scene_mug_stereo_textured.pcd",
                             "clouds/terrain_CSite1_red2-utm.pcd",
                             "clouds/tutorials_room_scan1.pcd"};
  for (const char* name : pcd_files) {
    pcl::PCLPointCloud2 cloud;
    ASSERT_EQ(pcl::io::loadPCDFile(sharedData(name), cloud), 0) << name;
    expectSameFloatsAsPCL(sharedData(name), cloud);
  }
}

// PCL has no OFF reader: the shared OFF files against the textbook one (counts, then strtod on
// every coordinate and index).
TEST(NumberParsing, EverySharedOffFileReadsAsStrtodReadsIt) {
  for (const char* name :
       {"meshes/bumpy.off", "meshes/bunny.off", "meshes/cow.off", "meshes/rocker-arm.off"}) {
    SCOPED_TRACE(name);
    std::ifstream in(sharedData(name));
    std::string magic, token;
    std::size_t vertices = 0, faces = 0, edges = 0;
    in >> magic >> vertices >> faces >> edges;
    const MeshFile file = readMeshFile(sharedData(name));
    ASSERT_EQ(static_cast<std::size_t>(file.positions.cols()), vertices);
    ASSERT_EQ(file.mesh.polygons.size(), faces);
    for (std::size_t i = 0; i < 3 * vertices; ++i) {
      in >> token;
      ASSERT_EQ(bitsOf(file.positions(static_cast<Eigen::Index>(i % 3),
                                      static_cast<Eigen::Index>(i / 3))),
                bitsOf(std::strtod(token.c_str(), nullptr)))
          << "vertex " << i / 3;
    }
    for (const pcl::Vertices& face : file.mesh.polygons) {
      std::size_t corners = 0;
      in >> corners;
      ASSERT_EQ(face.vertices.size(), corners);
      for (const pcl::index_t corner : face.vertices) {
        in >> token;
        ASSERT_EQ(corner, std::strtol(token.c_str(), nullptr, 10));
      }
      std::getline(in, token);  // colour values, if any
    }
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
