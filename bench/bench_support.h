#pragma once
// Shared by the benchmark programs: a large test mesh, and a main() that prints, after the usual
// Google Benchmark table, the ratio of every "baseline/<name>" to its "ours/<name>" counterpart
// measured in the same run.
#include <Eigen/Core>
#include <string>

namespace pcl_ddg {
namespace bench {

struct BenchMesh {
  Eigen::Matrix3Xd points;
  Eigen::Matrix3Xi triangles;
};

/** A torus (R = 1, r = 0.4) of around x tube vertices, triangulated as a regular grid. */
const BenchMesh& torusMesh(int around, int tube);

/** Also prints ours_name's time as a multiple of baseline_name's (for pairs whose names differ). */
void addRatio(const std::string& ours_name, const std::string& baseline_name);

/** Runs the registered benchmarks and prints the ratio table; returns main's exit code. */
int runWithRatios(int argc, char** argv);

}  // namespace bench
}  // namespace pcl_ddg
