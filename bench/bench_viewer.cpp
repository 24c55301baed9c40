// How responsive pcl_ddg_viewer is on a 1.15M-vertex mesh (the bench torus) and a 1.15M-point
// cloud (its vertices), in a window under Xvfb (run: xvfb-run -a bench/bench_viewer). Each
// benchmark times what a key press costs until the new frame is drawn (ViewerWindow::enqueue +
// runUntilIdle), against the same run's baseline: rendering what is on screen once (what a software
// OpenGL such as Xvfb's Mesa llvmpipe spends on 2.3M triangles; a GPU does it in milliseconds).
//   switch           area <-> angle normals, both already computed (the cache)
//   area_normals     area normals of new positions (after an untimed smoothing step)
//   cotan_curvature  the mean-curvature colour field of a new surface
//   pca_new_k        kd-tree PCA normals with a k not computed before
//   first_frame      a 1.15M-point cloud: model + window + first frame (time to first frame)
#include <benchmark/benchmark.h>
#include <pcl/conversions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vtkRenderWindow.h>

#include <filesystem>
#include <memory>

#include "bench_support.h"
#include "common/tool_input.h"
#include "pcl_ddg/io/mesh_io.h"
#include "viewer/viewer_window.h"

namespace pcl_ddg {
namespace bench {
namespace {

std::string folder() {
  static const std::string dir = [] {
    const auto path = std::filesystem::temp_directory_path() / "pcl_ddg_bench_viewer";
    std::filesystem::create_directories(path);
    return path.string();
  }();
  return dir;
}

// The torus as a binary PLY mesh and as a PCD cloud, written once.
const std::string& torusFile(bool mesh) {
  static const std::pair<std::string, std::string> files = [] {
    const BenchMesh& torus = torusMesh(1600, 720);
    pcl::PointCloud<pcl::PointXYZ> points;
    for (Eigen::Index v = 0; v < torus.points.cols(); ++v) {
      const Eigen::Vector3f p = torus.points.col(v).cast<float>();
      points.push_back({p.x(), p.y(), p.z()});
    }
    pcl::PolygonMesh polygon_mesh;
    pcl::toPCLPointCloud2(points, polygon_mesh.cloud);
    const std::string cloud_path = folder() + "/torus.pcd";
    saveMesh(cloud_path, polygon_mesh);
    polygon_mesh.polygons.resize(torus.triangles.cols());
    for (Eigen::Index t = 0; t < torus.triangles.cols(); ++t) {
      polygon_mesh.polygons[t].vertices = {torus.triangles(0, t), torus.triangles(1, t),
                                           torus.triangles(2, t)};
    }
    const std::string mesh_path = folder() + "/torus.ply";
    saveMesh(mesh_path, polygon_mesh);
    return std::make_pair(mesh_path, cloud_path);
  }();
  return mesh ? files.first : files.second;
}

struct Session {
  std::unique_ptr<viewer::ViewerModel> model;
  std::unique_ptr<viewer::ViewerWindow> window;
};

Session& meshSession() {
  static Session session = [] {
    Session s;
    const std::string& path = torusFile(true);
    s.model = std::make_unique<viewer::ViewerModel>(tools::ToolInput(path, "bench"), path);
    s.window = std::make_unique<viewer::ViewerWindow>(*s.model, 1024, 768);
    s.window->runUntilIdle(600.0);
    return s;
  }();
  return session;
}

void act(viewer::ViewerWindow& window, const std::string& action) {
  window.enqueue(action);
  if (!window.runUntilIdle(600.0)) throw std::runtime_error("timed out on " + action);
}

void redraw(benchmark::State& state) {
  Session& s = meshSession();
  for (auto _ : state) s.window->visualizer().getRenderWindow()->Render();
}
BENCHMARK(redraw)->Name("baseline/redraw")->Unit(benchmark::kMillisecond);

void switchMethod(benchmark::State& state) {
  Session& s = meshSession();
  act(*s.window, "method=angle");
  act(*s.window, "method=area");
  bool angle = true;
  for (auto _ : state) {
    act(*s.window, angle ? "method=angle" : "method=area");
    angle = !angle;
  }
}
BENCHMARK(switchMethod)->Name("ours/switch")->Unit(benchmark::kMillisecond);

// What a key costs on a surface seen for the first time: a smoothing step (not timed) makes new
// positions, shown with uniform normals and no colours; then the timed action computes on them.
void onNewPositions(benchmark::State& state, const char* action) {
  Session& s = meshSession();
  double time_step = 0.01;
  for (auto _ : state) {
    state.PauseTiming();
    const std::string setup[] = {"method=uniform", "field=none",
                                 "step=" + std::to_string(time_step), "smooth=implicit"};
    for (const std::string& untimed : setup) act(*s.window, untimed);
    state.ResumeTiming();
    act(*s.window, action);
    state.PauseTiming();
    act(*s.window, "undo");
    time_step *= 1.5;  // never the same surface twice
    state.ResumeTiming();
  }
}
BENCHMARK_CAPTURE(onNewPositions, area, "method=area")
    ->Name("ours/area_normals")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK_CAPTURE(onNewPositions, cotan, "field=mean")
    ->Name("ours/cotan_curvature")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

void pcaNewK(benchmark::State& state) {
  Session& s = meshSession();
  act(*s.window, "field=none");
  act(*s.window, "neighbours=kdtree");
  act(*s.window, "method=pca");
  int k = 10;
  for (auto _ : state) act(*s.window, "k=" + std::to_string(k++));
  act(*s.window, "method=area");
}
BENCHMARK(pcaNewK)->Name("ours/pca_new_k")->Unit(benchmark::kMillisecond)->Iterations(3);

void firstFrame(benchmark::State& state) {
  const std::string& path = torusFile(false);
  for (auto _ : state) {
    viewer::ViewerModel model(tools::ToolInput(path, "bench"), path);
    viewer::ViewerWindow window(model, 1024, 768);
    if (!window.runUntilIdle(600.0)) throw std::runtime_error("timed out");
  }
}
BENCHMARK(firstFrame)->Name("ours/cloud_first_frame")->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  pcl_ddg::bench::addRatio("ours/switch", "baseline/redraw");
  const int status = pcl_ddg::bench::runWithRatios(argc, argv);
  std::filesystem::remove_all(pcl_ddg::bench::folder());
  return status;
}
