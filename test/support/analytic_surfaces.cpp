#include "analytic_surfaces.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <utility>

namespace pcl_ddg {
namespace test {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct PointQuantities {
  Eigen::Vector3d point, normal, dir1, dir2;
  double kappa1 = 0.0, kappa2 = 0.0;
};

using Evaluator = std::function<PointQuantities(double u, double v)>;

void resize(SurfaceSample& s, Eigen::Index n) {
  s.points.resize(3, n);
  s.normals.resize(3, n);
  s.dir1.resize(3, n);
  s.dir2.resize(3, n);
  s.mean_curvature.resize(n);
  s.gauss_curvature.resize(n);
  s.kappa1.resize(n);
  s.kappa2.resize(n);
}

void store(SurfaceSample& s, Eigen::Index i, const PointQuantities& q) {
  s.points.col(i) = q.point;
  s.normals.col(i) = q.normal;
  s.dir1.col(i) = q.dir1;
  s.dir2.col(i) = q.dir2;
  s.kappa1[i] = q.kappa1;
  s.kappa2[i] = q.kappa2;
  s.mean_curvature[i] = 0.5 * (q.kappa1 + q.kappa2);
  s.gauss_curvature[i] = q.kappa1 * q.kappa2;
}

// Any unit tangent pair at an umbilic.
std::pair<Eigen::Vector3d, Eigen::Vector3d> tangentFrame(const Eigen::Vector3d& n) {
  const Eigen::Vector3d a =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = (a - a.dot(n) * n).normalized();
  return {t1, n.cross(t1)};
}

// A grid over [u0,u1] x [v0,v1] with nu x nv cells; a periodic direction does not repeat its last
// row. Interior parameters (all, in a periodic direction) are jittered by jitter * spacing.
SurfaceSample gridSurface(int nu, int nv, bool periodic_u, bool periodic_v, double u0, double u1,
                          double v0, double v1, const Sampling& sampling, const Evaluator& f) {
  const int cols = periodic_u ? nu : nu + 1;
  const int rows = periodic_v ? nv : nv + 1;
  const double du = (u1 - u0) / nu, dv = (v1 - v0) / nv;
  std::mt19937 rng(sampling.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  SurfaceSample s;
  resize(s, static_cast<Eigen::Index>(cols) * rows);
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      double u = u0 + i * du, v = v0 + j * dv;
      const bool edge_u = !periodic_u && (i == 0 || i == nu);
      const bool edge_v = !periodic_v && (j == 0 || j == nv);
      if (sampling.jitter > 0.0) {
        const double ju = unit(rng), jv = unit(rng);
        if (!edge_u) u += sampling.jitter * du * ju;
        if (!edge_v) v += sampling.jitter * dv * jv;
      }
      store(s, static_cast<Eigen::Index>(j) * cols + i, f(u, v));
    }
  }
  s.triangles.resize(3, 2 * static_cast<Eigen::Index>(nu) * nv);
  Eigen::Index t = 0;
  auto id = [&](int i, int j) { return (j % rows) * cols + (i % cols); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      s.triangles.col(t++) << a, b, c;
      s.triangles.col(t++) << a, c, d;
    }
  }
  return s;
}

// Graph z = f(x, y) with gradient (p, q) and Hessian (r, s; s, t), upward normal.
PointQuantities graphPoint(double x, double y, double z, double p, double q, double r, double s,
                           double t) {
  PointQuantities out;
  out.point = {x, y, z};
  const Eigen::Vector3d xu(1, 0, p), xv(0, 1, q);
  out.normal = xu.cross(xv).normalized();
  Eigen::Matrix2d first;
  first << 1 + p * p, p * q, p * q, 1 + q * q;
  // kappa is positive where the surface bends away from the normal: minus the classical form.
  Eigen::Matrix2d second;
  second << r, s, s, t;
  second *= -1.0 / std::sqrt(1 + p * p + q * q);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> eig(second, first);
  out.kappa2 = eig.eigenvalues()[0];
  out.kappa1 = eig.eigenvalues()[1];
  const Eigen::Matrix2d vecs = eig.eigenvectors();
  out.dir1 = (vecs(0, 1) * xu + vecs(1, 1) * xv).normalized();
  out.dir2 = (vecs(0, 0) * xu + vecs(1, 0) * xv).normalized();
  if (std::abs(out.kappa1 - out.kappa2) < 1e-14) {
    std::tie(out.dir1, out.dir2) = tangentFrame(out.normal);
  }
  return out;
}

// Midpoint-rule integrals over [-1,1]^2 of the area element sqrt(1 + p^2 + q^2) and of
// K dA = (r t - s^2) / (1 + p^2 + q^2)^(3/2) dx dy, the Monge patch's closed forms (independent of
// graphPoint's eigen-solve) for z = a (x^2 + sign_y y^2): p = 2ax, q = 2a sign_y y, rt - s^2 = 4a^2
// sign_y.
std::pair<double, double> graphIntegrals(double a, double sign_y) {
  const int n = 1000;
  const double h = 2.0 / n;
  double area = 0.0, total_k = 0.0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = -1 + (i + 0.5) * h, y = -1 + (j + 0.5) * h;
      const double g = 1 + 4 * a * a * (x * x + y * y);
      const double element = std::sqrt(g);
      area += element;
      total_k += 4 * a * a * sign_y / (g * element);
    }
  }
  return {area * h * h, total_k * h * h};
}

SurfaceSample graphSurface(const Sampling& sampling, double a, double sign_y) {
  const auto f = [a, sign_y](double x, double y) {
    return graphPoint(x, y, a * (x * x + sign_y * y * y), 2 * a * x, 2 * a * sign_y * y, 2 * a, 0,
                      2 * a * sign_y);
  };
  SurfaceSample s = gridSurface(sampling.resolution, sampling.resolution, false, false, -1, 1, -1,
                                1, sampling, f);
  std::tie(s.area, s.total_gauss_curvature) = graphIntegrals(a, sign_y);
  s.euler_characteristic = 1;
  return s;
}

}  // namespace

SurfaceSample& SurfaceSample::transform(const Eigen::Isometry3d& motion) {
  const Eigen::Matrix3d rotation = motion.linear();
  points = (rotation * points).colwise() + motion.translation();
  normals = rotation * normals;
  dir1 = rotation * dir1;
  dir2 = rotation * dir2;
  return *this;
}

SurfaceSample& SurfaceSample::rotateAndShiftFar() {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  motion.translation() = Eigen::Vector3d(1.0e5, -2.0e5, 0.5e5);
  return transform(motion);
}

SurfaceSample SurfaceSample::asCloud() const {
  SurfaceSample cloud = *this;
  cloud.triangles.resize(3, 0);
  return cloud;
}

SurfaceSample makePlane(const Sampling& sampling) {
  const auto f = [](double u, double v) {
    PointQuantities q;
    q.point = {u, v, 0};
    q.normal = Eigen::Vector3d::UnitZ();
    q.dir1 = Eigen::Vector3d::UnitX();
    q.dir2 = Eigen::Vector3d::UnitY();
    return q;
  };
  SurfaceSample s = gridSurface(sampling.resolution, sampling.resolution, false, false, -1, 1, -1,
                                1, sampling, f);
  s.area = 4.0;
  s.euler_characteristic = 1;
  return s;
}

SurfaceSample makeCylinder(const Sampling& sampling, double radius, double height) {
  const auto f = [radius](double u, double v) {
    PointQuantities q;
    q.normal = {std::cos(u), std::sin(u), 0};
    q.point = radius * q.normal + Eigen::Vector3d(0, 0, v);
    q.kappa1 = 1.0 / radius;
    q.dir1 = {-std::sin(u), std::cos(u), 0};
    q.dir2 = Eigen::Vector3d::UnitZ();
    return q;
  };
  const int around = sampling.resolution;
  const int rows = std::max(1, sampling.resolution / 2);
  SurfaceSample s =
      gridSurface(around, rows, true, false, 0, 2 * kPi, -height / 2, height / 2, sampling, f);
  s.area = 2 * kPi * radius * height;
  s.euler_characteristic = 0;
  return s;
}

SurfaceSample makeTorus(const Sampling& sampling, double major, double minor) {
  const auto f = [major, minor](double u, double v) {
    PointQuantities q;
    const double cu = std::cos(u), su = std::sin(u), cv = std::cos(v), sv = std::sin(v);
    q.normal = {cv * cu, cv * su, sv};
    q.point = Eigen::Vector3d((major + minor * cv) * cu, (major + minor * cv) * su, minor * sv);
    q.kappa1 = 1.0 / minor;                // around the tube (meridian)
    q.kappa2 = cv / (major + minor * cv);  // along the parallel
    q.dir1 = {-sv * cu, -sv * su, cv};
    q.dir2 = {-su, cu, 0};
    return q;
  };
  const int around = sampling.resolution;
  const int tube = std::max(3, sampling.resolution / 2);
  SurfaceSample s = gridSurface(around, tube, true, true, 0, 2 * kPi, 0, 2 * kPi, sampling, f);
  s.area = 4 * kPi * kPi * major * minor;
  s.euler_characteristic = 0;
  return s;
}

SurfaceSample makeSaddle(const Sampling& sampling, double a) {
  return graphSurface(sampling, a, -1);
}

SurfaceSample makeParaboloid(const Sampling& sampling, double a) {
  return graphSurface(sampling, a, 1);
}

std::vector<SurfaceFamily> analyticSurfaceFamilies(double jitter, std::uint32_t seed) {
  return {
      {"plane",
       [=](int r) {
         return makePlane({r, jitter, seed});
       }},
      {"sphere", [=](int r) { return makeIcosphere(r == 32 ? 4 : 5, 1.0, jitter, seed); }},
      {"cylinder",
       [=](int r) {
         return makeCylinder({2 * r, jitter, seed});
       }},
      {"torus",
       [=](int r) {
         return makeTorus({2 * r, jitter, seed});
       }},
      {"saddle",
       [=](int r) {
         return makeSaddle({r, jitter, seed});
       }},
      {"paraboloid",
       [=](int r) {
         return makeParaboloid({r, jitter, seed});
       }},
  };
}

SurfaceSample makeIcosphere(int level, double radius, double jitter, std::uint32_t seed) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return midpoint[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    next.reserve(f.size() * 4);
    for (const auto& t : f) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f.swap(next);
  }
  if (jitter > 0.0) {
    // Gaussian jitter (standard deviation jitter * edge length per coordinate), then back onto
    // the sphere.
    const double h = (v[f[0][0]] - v[f[0][1]]).norm();
    std::mt19937 rng(seed);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (auto& p : v) {
      const Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
      p = (p + jitter * h * d).normalized();
    }
  }
  SurfaceSample s;
  resize(s, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    PointQuantities q;
    q.normal = v[i];
    q.point = radius * v[i];
    q.kappa1 = q.kappa2 = 1.0 / radius;
    std::tie(q.dir1, q.dir2) = tangentFrame(q.normal);
    store(s, static_cast<Eigen::Index>(i), q);
  }
  s.triangles.resize(3, static_cast<Eigen::Index>(f.size()));
  for (std::size_t t = 0; t < f.size(); ++t) s.triangles.col(static_cast<Eigen::Index>(t)) = f[t];
  s.area = 4 * kPi * radius * radius;
  s.total_gauss_curvature = 4 * kPi;
  s.euler_characteristic = 2;
  return s;
}

}  // namespace test
}  // namespace pcl_ddg
