#pragma once
// Analytic test surfaces with exact differential quantities at every vertex.
//
// Orientation: normals point "outward" (sphere, cylinder, torus) or along +z before the rigid
// motion (plane, saddle, paraboloid). Curvature sign: kappa > 0 where the surface bends away from
// the normal, so the outward unit sphere has kappa1 = kappa2 = H = 1 and K = 1.
// kappa1 >= kappa2; dir1, dir2 are the matching unit principal directions (arbitrary orthonormal
// tangents at umbilics).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <vector>

namespace pcl_ddg {
namespace test {

struct SurfaceSample {
  Eigen::Matrix3Xd points;
  Eigen::Matrix3Xi triangles;  ///< empty for a cloud
  Eigen::Matrix3Xd normals;
  Eigen::VectorXd mean_curvature, gauss_curvature, kappa1, kappa2;
  Eigen::Matrix3Xd dir1, dir2;
  /** Exact surface area, and the exact integral of K over it. */
  double area = 0.0;
  double total_gauss_curvature = 0.0;
  /** Euler characteristic of the surface the mesh represents. */
  int euler_characteristic = 0;

  /** Rotates about the origin, then translates; quantities move with the surface. */
  SurfaceSample& transform(const Eigen::Isometry3d& motion);
  /** The usual test motion: a generic rotation and a shift of about 1e5 from the origin. */
  SurfaceSample& rotateAndShiftFar();
  /** Drops the faces (a point cloud of the same samples). */
  SurfaceSample asCloud() const;
};

/** Gaussian parameter jitter, standard deviation as a fraction of the grid spacing (0 = regular);
 *  boundary rows of an open direction stay on the boundary. */
struct Sampling {
  int resolution = 16;
  double jitter = 0.0;
  std::uint32_t seed = 1;
};

/** Square [-1,1]^2 in z = 0, (resolution+1)^2 vertices. Open (chi = 1). */
SurfaceSample makePlane(const Sampling& sampling);
/** Icosphere of radius r: level L has 10*4^L + 2 vertices; jitter is Gaussian
 *  (standard deviation jitter x edge length per coordinate), reprojected onto the sphere. */
SurfaceSample makeIcosphere(int level, double radius = 1.0, double jitter = 0.0,
                            std::uint32_t seed = 1);
/** Open cylinder x^2 + y^2 = r^2, |z| <= height/2 (resolution around, resolution/2 rows). */
SurfaceSample makeCylinder(const Sampling& sampling, double radius = 1.0, double height = 2.0);
/** Torus with major radius R, minor radius r: resolution x resolution/2 grid. */
SurfaceSample makeTorus(const Sampling& sampling, double major = 1.0, double minor = 0.4);
/** Saddle z = a (x^2 - y^2) over [-1,1]^2. */
SurfaceSample makeSaddle(const Sampling& sampling, double a = 0.5);
/** Paraboloid z = a (x^2 + y^2) over [-1,1]^2. */
SurfaceSample makeParaboloid(const Sampling& sampling, double a = 0.5);

/** One surface of the convergence tests, made at a resolution of 32 or 64. */
struct SurfaceFamily {
  const char* name;
  std::function<SurfaceSample(int resolution)> make;
};
/** Plane, sphere, cylinder, torus, saddle and paraboloid with the same jitter and seed, sampled so
 *  that resolutions 32 and 64 give about 1k and 4k points (the sphere: icosphere levels 4 and 5;
 *  the closed cylinder and torus twice as many columns). */
std::vector<SurfaceFamily> analyticSurfaceFamilies(double jitter, std::uint32_t seed);

}  // namespace test
}  // namespace pcl_ddg
