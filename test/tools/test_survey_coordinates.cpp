// The fitting tools on survey coordinates (local_cloud.h): a shape with exact normals (a sphere
// beside a height field) at the origin and again at (5e5, 5e6, 200), as a double PLY and as a LAS
// file (scale 0.001, offset at the survey's place). The far files must give the normals of the
// near one, and those of an independent double PCA of the same points; in memory and in pieces
// (-memory) alike. The quantum warning fires where the file's own coordinates are coarse (a float
// field far away, a coarse LAS scale), whatever the format, and nowhere else.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "estimator_support.h"
#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

const Eigen::Vector3d kOffset(5e5, 5e6, 200.0);

// A sphere of radius 20 (uniform on it) beside a jittered 100 x 100 height field of spacing 1,
// z = 2 sin(x / 7) cos(y / 5), on a millimetre grid (what a LAS file of scale 0.001 holds).
Eigen::Matrix3Xd scene() {
  std::mt19937 random(11);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  const int sphere = 12000, grid = 100;
  Eigen::Matrix3Xd p(3, sphere + grid * grid);
  for (int i = 0; i < sphere; ++i) {
    Eigen::Vector3d d(gauss(random), gauss(random), gauss(random));
    p.col(i) = Eigen::Vector3d(150.0, 0.0, 0.0) + 20.0 * d.normalized();
  }
  for (int r = 0; r < grid; ++r) {
    for (int c = 0; c < grid; ++c) {
      const double x = c - 50.0 + jitter(random), y = r - 50.0 + jitter(random);
      p.col(sphere + r * grid + c) << x, y, 2.0 * std::sin(x / 7.0) * std::cos(y / 5.0);
    }
  }
  return p.unaryExpr([](double v) { return std::round(v * 1000.0) / 1000.0; });
}

void save(const std::string& path, const Eigen::Matrix3Xd& positions, FieldPrecision precision,
          std::shared_ptr<const LasLayout> las = nullptr) {
  pcl::PolygonMesh mesh = makeMesh(positions, {});
  setVertexCoordinates(mesh.cloud, positions, precision);
  MeshWriteOptions options;
  options.las = std::move(las);
  saveMesh(path, mesh, options);
}

std::shared_ptr<const LasLayout> lasLayout(double scale) {
  auto las = std::make_shared<LasLayout>();
  las->scale = Eigen::Vector3d::Constant(scale);
  las->offset = kOffset;
  return las;
}

Eigen::Matrix3Xd normalsIn(const std::string& path) {
  const MeshFile file = readMeshFile(path);
  Eigen::Matrix3Xd n(3, file.positions.cols());
  const bool ply = hasVertexField(file.mesh.cloud, "nx");
  const char* names[2][3] = {{"normal_x", "normal_y", "normal_z"}, {"nx", "ny", "nz"}};
  for (int d = 0; d < 3; ++d)
    n.row(d) = vertexScalarField(file.mesh.cloud, names[ply][d]).transpose();
  return n;
}

double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

struct Agreement {
  double max = 0.0;  ///< radians
  long beyond = 0;   ///< points more than 1e-6 rad apart
  long invalid = 0;  ///< NaN in either
};

Agreement agreement(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  Agreement g;
  for (Eigen::Index i = 0; i < a.cols(); ++i) {
    if (!a.col(i).allFinite() || !b.col(i).allFinite()) {
      ++g.invalid;
      continue;
    }
    const double d = angle(a.col(i), b.col(i));
    g.max = std::max(g.max, d);
    g.beyond += d > 1e-6;
  }
  return g;
}

class SurveyCoordinates : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new std::string(scratchFolder("survey_coordinates"));
    const Eigen::Matrix3Xd near = scene();
    save(path("near.ply"), near, FieldPrecision::Double);
    save(path("far.ply"), near.colwise() + kOffset, FieldPrecision::Double);
    save(path("far.las"), near.colwise() + kOffset, FieldPrecision::Double, lasLayout(0.001));
    const std::string options = " -method pca -k 16 -orient up";
    for (const char* name : {"near.ply", "far.ply", "far.las"}) {
      const ToolRun run =
          runTool(PCL_DDG_NORMALS_TOOL,
                  path(name) + " " + path(std::string("n_") + name + ".ply") + options);
      ASSERT_EQ(run.exit_code, 0) << run.err;
      EXPECT_EQ(run.err.find("the coordinates are rounded to"), std::string::npos) << run.err;
    }
  }
  static std::string path(const std::string& name) { return *folder_ + "/" + name; }
  static std::string* folder_;
};
std::string* SurveyCoordinates::folder_ = nullptr;

// Two frames' floats may order a near tie of distances either way (and fit another k-th
// neighbour): at most 0.2 % of the points, the rest within the float output's rounding.
TEST_F(SurveyCoordinates, FarDoublePlyAndLasGiveTheNormalsOfTheShapeAtTheOrigin) {
  const Eigen::Matrix3Xd near = normalsIn(path("n_near.ply.ply"));
  for (const char* far : {"n_far.ply.ply", "n_far.las.ply"}) {
    const Agreement g = agreement(normalsIn(path(far)), near);
    EXPECT_EQ(g.invalid, 0) << far;
    EXPECT_LE(g.beyond, near.cols() / 500) << far << ": max " << g.max;
  }
}

// The fit shifts a tool's own positions about the local origin and back, or keeps a float
// cloud's only in its floats, then in its rows: the output's coordinates are the input's to the
// last bit (a double PLY far away, one whose floats about its origin are exact but not its rows'
// floats, and double and float ones around the origin with -0 in them, which a shift by 0 and
// back would turn into +0; float ones written as doubles), every fitting tool.
TEST_F(SurveyCoordinates, TheOutputsCoordinatesAreTheInputsBitForBit) {
  Eigen::Matrix3Xd signed_zeros = scene();
  for (Eigen::Index i = 0; i < signed_zeros.cols(); i += 7) signed_zeros(2, i) = -0.0;
  save(path("zeros.ply"), signed_zeros, FieldPrecision::Double);
  save(path("zeros_float.ply"), signed_zeros.cast<float>().cast<double>(), FieldPrecision::Float);
  save(path("far_float.ply"),
       (signed_zeros.colwise() + Eigen::Vector3d(4096.0, -8192.0, 512.0))
           .cast<float>()
           .cast<double>(),
       FieldPrecision::Float);
  // A point with one NaN coordinate, its others anywhere: left as read (not shifted).
  Eigen::Matrix3Xd partly = scene().colwise() + kOffset;
  partly(1, 3) = std::numeric_limits<double>::quiet_NaN();
  partly(0, 3) = 1e-300;
  save(path("far_nan.ply"), partly, FieldPrecision::Double);
  // Quarters of a metre 5,000 km away: exact in float about the origin, not in a float row;
  // heights about 0 with -0 among them (restored from the floats, they stay -0).
  Eigen::Matrix3Xd quarters =
      scene().unaryExpr([](double v) { return std::round(v * 4.0) / 4.0; }).colwise() +
      Eigen::Vector3d(kOffset.x(), kOffset.y(), 0.0);
  for (Eigen::Index i = 0; i < quarters.cols(); i += 7) quarters(2, i) = -0.0;
  save(path("far_quarters.ply"), quarters, FieldPrecision::Double);
  const auto same = [](double a, double b) {
    return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0;
  };
  for (const char* name :
       {"far.ply", "zeros.ply", "zeros_float.ply", "far_float.ply", "far_nan.ply", "far.las",
        "far_quarters.ply", "zeros_float.ply -precision double"}) {
    const std::string file = std::string(name).substr(0, std::string(name).find(' '));
    const std::string options = std::string(name).substr(file.size());
    const Eigen::Matrix3Xd in = readMeshFile(path(file)).positions;
    for (const char* tool : {PCL_DDG_NORMALS_TOOL, PCL_DDG_CURVATURE_TOOL}) {
      const std::string out = path("same_" + file);
      const ToolRun run =
          runTool(tool, path(file) + " " + out + " -method quadric -k 16" + options);
      ASSERT_EQ(run.exit_code, 0) << run.err;
      const Eigen::Matrix3Xd got = readMeshFile(out).positions;
      ASSERT_EQ(got.cols(), in.cols());
      for (Eigen::Index i = 0; i < in.size(); ++i)
        ASSERT_TRUE(same(got.data()[i], in.data()[i])) << tool << " " << name << " value " << i;
    }
  }
}

// Independent of the library: each sampled point's 16 nearest by brute force on the coordinates
// read back from the LAS file (long double distances), their covariance about their mean, and
// Eigen's eigenvector of its smallest eigenvalue.
TEST_F(SurveyCoordinates, FarLasNormalsEqualAnIndependentDoublePCA) {
  const Eigen::Matrix3Xd world = readMeshFile(path("far.las")).positions;
  ASSERT_GT(world.row(1).minCoeff(), 4.9e6);
  const Eigen::Matrix3Xd ours = normalsIn(path("n_far.las.ply"));
  const int k = 16;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < world.cols(); i += 97)
    worst = std::max(worst, angle(ours.col(i), bruteForcePcaNormal(world, i, k)));
  EXPECT_LE(worst, 1e-6);
}

// -memory reads the file in pieces and fits tiles about the whole file's local origin: the
// in-memory normals, bit for bit.
TEST_F(SurveyCoordinates, PiecesGiveTheInMemoryNormals) {
  for (const char* name : {"far.ply", "far.las"}) {
    const std::string out = path(std::string("m_") + name + ".ply");
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, path(name) + " " + out +
                                                          " -method pca -k 16 -orient up "
                                                          "-memory 8M");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    ASSERT_NE(run.err.find("tiles of at most"), std::string::npos) << run.err;
    const Eigen::Matrix3Xd a = normalsIn(out),
                           b = normalsIn(path(std::string("n_") + name + ".ply"));
    ASSERT_EQ(a.cols(), b.cols());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof(double) * a.size()), 0) << name;
  }
}

// A LAS file fitted without -viewpoint or -orient is oriented up, and says so; a viewpoint
// chooses otherwise.
TEST_F(SurveyCoordinates, LasFilesAreOrientedUpByDefault) {
  for (const char* memory : {"", " -memory 8M"}) {
    const ToolRun run =
        runTool(PCL_DDG_NORMALS_TOOL, path("far.las") + " " + path("up.ply") + " -k 16" + memory);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("a LAS file: normals oriented up"), std::string::npos) << run.err;
    const Eigen::Matrix3Xd n = normalsIn(path("up.ply"));
    EXPECT_GE(n.row(2).minCoeff(), 0.0) << memory;
  }
  const std::string below = std::to_string(kOffset.x() + 150.0) + "," +
                            std::to_string(kOffset.y()) + "," + std::to_string(kOffset.z() - 1e3);
  const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, path("far.las") + " " + path("down.ply") +
                                                        " -k 16 -viewpoint " + below);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("oriented up"), std::string::npos) << run.err;
  const Eigen::Matrix3Xd n = normalsIn(path("down.ply"));
  EXPECT_GT((n.row(2).array() < 0.0).count(), n.cols() / 2);  // the field faces the viewpoint
  // The curvature tool orients its quadrics the same way.
  const ToolRun curvature =
      runTool(PCL_DDG_CURVATURE_TOOL, path("far.las") + " " + path("c.ply") + " -method quadric");
  ASSERT_EQ(curvature.exit_code, 0) << curvature.err;
  EXPECT_NE(curvature.err.find("a LAS file: normals oriented up"), std::string::npos);
}

// The quantum warning says what the file holds: a float field far away steps by 0.5 m at 5e6 and
// a LAS scale of 1 by 1 m, coarser than half the spacing; doubles and a millimetre scale do not.
TEST_F(SurveyCoordinates, TheQuantumWarningFollowsTheFilesOwnCoordinates) {
  const Eigen::Matrix3Xd far = scene().colwise() + kOffset;
  struct Case {
    std::string name;
    FieldPrecision precision;
    double las_scale;  ///< 0: not LAS
    bool warns;
  };
  const Case cases[] = {{"f.ply", FieldPrecision::Float, 0.0, true},
                        {"f.pcd", FieldPrecision::Float, 0.0, true},
                        {"d.ply", FieldPrecision::Double, 0.0, false},
                        {"d.pcd", FieldPrecision::Double, 0.0, false},
                        {"coarse.las", FieldPrecision::Double, 1.0, true},
                        {"fine.las", FieldPrecision::Double, 0.001, false}};
  for (const Case& c : cases) {
    save(path(c.name), far, c.precision, c.las_scale > 0.0 ? lasLayout(c.las_scale) : nullptr);
    const ToolRun run =
        runTool(PCL_DDG_NORMALS_TOOL, path(c.name) + " " + path("q.ply") + " -k 16 -orient up");
    ASSERT_EQ(run.exit_code, 0) << c.name << ": " << run.err;
    EXPECT_EQ(run.err.find("the coordinates are rounded to") != std::string::npos, c.warns)
        << c.name << ": " << run.err;
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
