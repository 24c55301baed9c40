// pcl_ddg_viewer under Xvfb (ctest runs this program through xvfb-run): actions and keys reach the
// same state; pictures are checked by their properties (coverage, colours, glyphs, silhouettes),
// never pixel by pixel against a stored image; every shared file opens; errors are one line.
#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <vtkActor2DCollection.h>
#include <vtkCamera.h>

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkScalarBarActor.h>
#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "analytic_surfaces.h"
#include "common/tool_input.h"
#include "common/tool_output.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "test_data.h"
#include "tool_runner.h"
#include "viewer/hidden_faces.h"
#include "viewer/viewer_window.h"
#include "x_keyboard.h"

namespace pcl_ddg {
namespace test {
namespace {

using viewer::ViewerModel;
using viewer::ViewerState;
using viewer::ViewerWindow;

// The viewer's background, (0.12, 0.12, 0.14) in 8 bits.
bool isBackground(const unsigned char* p) {
  return std::abs(p[0] - 31) <= 2 && std::abs(p[1] - 31) <= 2 && std::abs(p[2] - 36) <= 2;
}

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  const unsigned char* at(int x, int y) const { return rgb.data() + 3 * (y * width + x); }
  /** Pixels of the object: not background, and above the overlay text (the bottom 20%) and below
   *  the method names and the colour bar (the top 22%). */
  template <typename F>
  void forObject(F f) const {
    for (int y = height * 22 / 100; y < height * 80 / 100; ++y) {
      for (int x = 0; x < width; ++x) {
        if (!isBackground(at(x, y))) f(at(x, y));
      }
    }
  }
  double objectShare() const {
    std::int64_t n = 0;
    forObject([&](const unsigned char*) { ++n; });
    return static_cast<double>(n) / (width * height * 58 / 100);
  }
};

// Whether the object band (forObject's rows) of two pictures is identical: the overlay text below
// it names the last computation's time, which differs between runs.
bool sameObject(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) return false;
  const std::size_t begin = 3 * static_cast<std::size_t>(a.width) * (a.height * 22 / 100);
  const std::size_t end = 3 * static_cast<std::size_t>(a.width) * (a.height * 80 / 100);
  return std::equal(a.rgb.begin() + begin, a.rgb.begin() + end, b.rgb.begin() + begin);
}

Image readPng(const std::string& path) {
  Image image;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
  if (data == nullptr) ADD_FAILURE() << "cannot read " << path;
  if (data == nullptr) return image;
  image.rgb.assign(data, data + 3 * image.width * image.height);
  stbi_image_free(data);
  return image;
}

std::int64_t differingPixels(const Image& a, const Image& b) {
  std::int64_t n = 0;
  for (std::size_t i = 0; i + 2 < a.rgb.size() && i + 2 < b.rgb.size(); i += 3) {
    n += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
  }
  return n;
}

// A sphere with radial noise (5% of the radius): smoothing visibly rounds its silhouette.
std::string noisySphereFile(const std::string& dir) {
  SurfaceSample sphere = makeIcosphere(4);
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (Eigen::Index i = 0; i < sphere.points.cols(); ++i)
    sphere.points.col(i) *= 1.0 + noise(random);
  std::vector<std::vector<int>> faces;
  for (Eigen::Index t = 0; t < sphere.triangles.cols(); ++t) {
    faces.push_back({sphere.triangles(0, t), sphere.triangles(1, t), sphere.triangles(2, t)});
  }
  const std::string path = dir + "/noisy_sphere.ply";
  saveMesh(path, makeMesh(sphere.points, faces));
  return path;
}

class Viewer : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::unique_ptr<ViewerModel> open(const std::string& path) {
    return std::make_unique<ViewerModel>(tools::ToolInput(path, "test_viewer"), path);
  }
  Image screenshot(ViewerWindow& window, const std::string& name) {
    EXPECT_TRUE(window.runUntilIdle(120.0));
    const std::string path = dir_ + "/" + name + ".png";
    window.saveScreenshot(path);
    return readPng(path);
  }
  std::string dir_;
};

void pressKey(ViewerWindow& window, const std::string& key_sym, char key_code) {
  vtkRenderWindowInteractor* interactor = window.interactor();
  interactor->SetKeyEventInformation(0, 0, key_code, 1, key_sym.c_str());
  interactor->InvokeEvent(vtkCommand::KeyPressEvent);
  interactor->InvokeEvent(vtkCommand::KeyReleaseEvent);
}

TEST_F(Viewer, KeysReachTheSameStateAsTheEquivalentDoLine) {
  auto model = open(sharedData("meshes/bunny.off"));
  ViewerWindow by_keys(*model, 400, 300);
  const std::pair<const char*, char> keys[] = {{"m", 'm'},
                                               {"m", 'm'},
                                               {"bracketright", ']'},
                                               {"bracketright", ']'},
                                               {"bracketleft", '['},
                                               {"n", 'n'},
                                               {"v", 'v'},
                                               {"v", 'v'},
                                               {"b", 'b'},
                                               {"semicolon", ';'},
                                               {"period", '.'},
                                               {"i", 'i'},
                                               {"y", 'y'},
                                               {"d", 'd'},
                                               {"comma", ','},
                                               {"t", 't'},
                                               {"z", 'z'},
                                               {"i", 'i'}};
  for (const auto& [sym, code] : keys) pressKey(by_keys, sym, code);
  ASSERT_TRUE(by_keys.runUntilIdle(120.0));

  ViewerWindow by_actions(*model, 400, 300);
  for (const std::string& action : viewer::splitActions(
           "method=mean_curvature k=20 k=25 k=20 neighbours=kdtree field=gauss normals=on "
           "shading=flat step=2 smooth=implicit weights=uniform frozen=off step=1 smooth=explicit "
           "undo smooth=implicit")) {
    by_actions.enqueue(action);
  }
  ASSERT_TRUE(by_actions.runUntilIdle(120.0));
  EXPECT_TRUE(by_keys.errors().empty());
  EXPECT_TRUE(by_actions.errors().empty());
  EXPECT_EQ(by_keys.state(), by_actions.state());
  EXPECT_EQ(by_keys.state().method, viewer::NormalMethod::MeanCurvature);
  EXPECT_EQ(by_keys.state().steps.size(), 2u);
  EXPECT_EQ(*by_keys.frame().positions, *by_actions.frame().positions);
}

TEST_F(Viewer, PicturesShowTheObjectTheFieldsAndTheGlyphs) {
  auto model = open(sharedData("meshes/cow.off"));
  ViewerWindow window(*model, 480, 360);
  const Image none = screenshot(window, "none");
  EXPECT_GT(none.objectShare(), 0.05);
  EXPECT_LT(none.objectShare(), 0.9);
  // Uncoloured is grey: the lit surface has no hue.
  int most_saturated = 0;
  none.forObject([&](const unsigned char* p) {
    most_saturated = std::max({most_saturated, std::abs(p[0] - p[1]), std::abs(p[1] - p[2])});
  });
  EXPECT_LE(most_saturated, 6);

  window.enqueue("field=mean");
  const Image mean = screenshot(window, "mean");
  window.enqueue("field=gauss");
  const Image gauss = screenshot(window, "gauss");
  EXPECT_GT(differingPixels(none, mean), 1000);
  EXPECT_GT(differingPixels(mean, gauss), 1000);
  int colourful = 0;
  mean.forObject([&](const unsigned char* p) { colourful += std::abs(p[0] - p[2]) > 40; });
  EXPECT_GT(colourful, 500);

  const auto yellow = [](const Image& image) {
    int n = 0;
    image.forObject([&](const unsigned char* p) { n += p[0] > 200 && p[1] > 170 && p[2] < 90; });
    return n;
  };
  window.enqueue("field=none");
  window.enqueue("normals=on");
  const Image glyphs = screenshot(window, "glyphs");
  EXPECT_GT(yellow(glyphs), yellow(none) + 500);
}

TEST_F(Viewer, SmoothingChangesTheSilhouetteAndUndoRestoresItExactly) {
  auto model = open(noisySphereFile(dir_));
  ViewerWindow window(*model, 400, 400);
  const Image before = screenshot(window, "before");
  window.enqueue("smooth=implicit:4");
  const Image smoothed = screenshot(window, "smoothed");
  std::int64_t silhouette_changed = 0;
  for (int y = 0; y < before.height; ++y) {
    for (int x = 0; x < before.width; ++x) {
      silhouette_changed += isBackground(before.at(x, y)) != isBackground(smoothed.at(x, y));
    }
  }
  EXPECT_GT(silhouette_changed, 200);
  EXPECT_NE(*window.frame().positions, model->inputPositions());

  window.enqueue("undo");
  const Image undone = screenshot(window, "undone");
  EXPECT_TRUE(window.frame().positions->cwiseEqual(model->inputPositions()).all());
  EXPECT_TRUE(sameObject(undone, before)) << differingPixels(undone, before) << " pixels differ";
}

TEST_F(Viewer, TaubinAndUmbrellaStepsAreTheLibrarys) {
  const std::string file = noisySphereFile(dir_);
  auto model = open(file);
  const MeshFile mesh = readMeshFile(file);
  const MeshTopology topology(mesh.mesh);
  // The library's runs the viewer's steps stand for (operator frozen, the viewer's default).
  const auto library = [&](SmoothingScheme scheme, int iterations) {
    MeshSmoothingParameters p;
    p.scheme = scheme;
    p.weights = LaplacianWeights::Uniform;
    p.average = FlowAverage::Degree;
    p.time_step = 0.5;  // explicit: the step given; Taubin: lambda (mu -0.53)
    p.iterations = iterations;
    return smoothMeshPositions(topology, mesh.positions, p);
  };
  ViewerWindow window(*model, 200, 200);
  for (const char* action : {"weights=umbrella", "smooth=explicit:0.5", "smooth=explicit"})
    window.enqueue(action);
  ASSERT_TRUE(window.runUntilIdle(60.0));
  EXPECT_TRUE(window.errors().empty());
  EXPECT_EQ(*window.frame().positions, library(SmoothingScheme::Explicit, 2));
  for (const char* action : {"undo", "undo", "smooth=taubin", "smooth=taubin", "smooth=taubin"})
    window.enqueue(action);
  ASSERT_TRUE(window.runUntilIdle(60.0));
  EXPECT_EQ(*window.frame().positions, library(SmoothingScheme::Taubin, 3));
  EXPECT_NE(*window.frame().positions, library(SmoothingScheme::Explicit, 3));
}

// The pixels of the object band (forObject's rows: the text above and below it names the last
// computation's time) where two pictures differ, and how many of them lie within two pixels of
// the background of either (on the outline).
std::pair<std::int64_t, std::int64_t> differencesOnOutline(const Image& a, const Image& b) {
  std::int64_t differ = 0, on_outline = 0;
  for (int y = a.height * 22 / 100; y < a.height * 80 / 100; ++y) {
    for (int x = 2; x + 2 < a.width; ++x) {
      if (std::equal(a.at(x, y), a.at(x, y) + 3, b.at(x, y))) continue;
      ++differ;
      bool near_background = false;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          near_background |=
              isBackground(a.at(x + dx, y + dy)) || isBackground(b.at(x + dx, y + dy));
        }
      }
      on_outline += near_background;
    }
  }
  return {differ, on_outline};
}

// Back faces are left out only where none can be seen: the picture is the same without them, but
// for a few pixels where a back face sharing an edge with a front face may cover a pixel's centre
// or win its depth test: on the outline, or on a spike's outline in front of the sphere.
TEST_F(Viewer, BackFacesAreCulledOnlyWhereNoneCanBeSeen) {
  auto model = open(noisySphereFile(dir_));
  ViewerWindow window(*model, 400, 400);
  screenshot(window, "placed");
  // Zoomed out to the object band: the text above and below (the computation's time) differs.
  window.sceneRenderer()->GetActiveCamera()->Zoom(0.6);
  const Image culled = screenshot(window, "culled");
  EXPECT_TRUE(window.culledBackFaces());
  window.setHiddenFaceCulling(false);
  const Image all_faces = screenshot(window, "all_faces");
  EXPECT_FALSE(window.culledBackFaces());
  const auto [differ, on_outline] = differencesOnOutline(culled, all_faces);
  std::printf("%lld pixels differ, %lld of them on the outline\n", static_cast<long long>(differ),
              static_cast<long long>(on_outline));
  EXPECT_LT(differ, culled.objectShare() * culled.width * culled.height / 1000);

  // As a wireframe (PCL's key w) the back faces' edges show.
  window.setHiddenFaceCulling(true);
  pressKey(window, "w", 'w');
  screenshot(window, "wireframe");
  EXPECT_FALSE(window.culledBackFaces());
  pressKey(window, "s", 's');
  screenshot(window, "surface");
  EXPECT_TRUE(window.culledBackFaces());

  // From the centre of the sphere every face in sight is a back face: none may be culled.
  vtkRenderer* renderer = window.visualizer().getRendererCollection()->GetFirstRenderer();
  renderer->GetActiveCamera()->SetPosition(0.0, 0.0, 0.0);
  renderer->GetActiveCamera()->SetFocalPoint(0.0, 0.0, -1.0);
  renderer->ResetCameraClippingRange();
  const Image inside = screenshot(window, "inside");
  EXPECT_FALSE(window.culledBackFaces());
  EXPECT_GT(inside.objectShare(), 0.95);
}

// Normals shown before are drawn again from VTK's buffers: the picture is the one first drawn.
TEST_F(Viewer, SwitchingBackToNormalsShownBeforeDrawsTheSamePicture) {
  auto model = open(sharedData("meshes/cow.off"));
  ViewerWindow window(*model, 400, 300);
  window.enqueue("field=mean");
  const Image area = screenshot(window, "area");
  window.enqueue("method=uniform");
  window.enqueue("field=none");
  const Image uniform = screenshot(window, "uniform");
  EXPECT_GT(differingPixels(area, uniform), 1000);
  window.enqueue("method=area");
  window.enqueue("field=mean");
  const Image area_again = screenshot(window, "area_again");
  EXPECT_TRUE(sameObject(area, area_again)) << differingPixels(area, area_again) << " differ";
}

// A cloud with colours (PLY red green blue) opens in them: left half red, right half blue.
TEST_F(Viewer, ACloudWithColoursIsDrawnInThemAndFieldRgbNamesThem) {
  const std::string file = dir_ + "/coloured.ply";
  {
    std::ofstream out(file);
    const int side = 80;
    out << "ply\nformat ascii 1.0\nelement vertex " << side * side
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nend_header\n";
    for (int i = 0; i < side; ++i) {
      for (int j = 0; j < side; ++j) {
        const bool left = i < side / 2;
        out << (i - side / 2) * 0.01 << " " << (j - side / 2) * 0.01 << " 2 "
            << (left ? "255 0 0\n" : "0 0 255\n");
      }
    }
  }
  auto model = open(file);
  ViewerWindow window(*model, 400, 300);
  const auto count = [](const Image& image, int channel) {
    std::int64_t n = 0;
    image.forObject([&](const unsigned char* p) {
      n += p[channel] > 150 && p[(channel + 1) % 3] < 90 && p[(channel + 2) % 3] < 90;
    });
    return n;
  };
  const Image coloured = screenshot(window, "rgb");
  EXPECT_EQ(window.state().field, "rgb");
  EXPECT_GT(count(coloured, 0), 1000);  // red
  EXPECT_GT(count(coloured, 2), 1000);  // blue
  window.enqueue("field=none");
  const Image plain = screenshot(window, "none");
  EXPECT_LT(count(plain, 0), 50);
  window.enqueue("field=rgb");
  const Image again = screenshot(window, "rgb_again");
  EXPECT_GT(count(again, 0), 1000);
  EXPECT_TRUE(window.errors().empty());
  // Without colours there is no rgb to show.
  viewer::InputCapabilities plain_mesh;
  plain_mesh.is_mesh = true;
  plain_mesh.points = 100;
  ViewerState state = viewer::initialState(plain_mesh);
  EXPECT_EQ(state.field, "none");
  EXPECT_THROW(viewer::applyAction(state, plain_mesh, "field=rgb"), std::invalid_argument);
}

// Where the input's points land on the screen, by VTK's own projection: the share of the frame's
// width and height they span, and whether all are inside it.
struct Framing {
  double width = 0.0, height = 0.0;
  bool inside = true;
};
Framing framingOf(ViewerWindow& window, const Eigen::Matrix3Xd& positions) {
  vtkRenderer* renderer = window.sceneRenderer();
  const int* size = renderer->GetSize();
  double low[2] = {1e300, 1e300}, high[2] = {-1e300, -1e300};
  Framing framing;
  for (Eigen::Index i = 0; i < positions.cols();
       i += std::max<Eigen::Index>(1, positions.cols() / 5000)) {
    if (!positions.col(i).allFinite()) continue;
    renderer->SetWorldPoint(positions(0, i), positions(1, i), positions(2, i), 1.0);
    renderer->WorldToDisplay();
    const double* d = renderer->GetDisplayPoint();
    for (int k = 0; k < 2; ++k) {
      low[k] = std::min(low[k], d[k]);
      high[k] = std::max(high[k], d[k]);
    }
    framing.inside = framing.inside && d[0] >= 0 && d[1] >= 0 && d[0] <= size[0] && d[1] <= size[1];
  }
  framing.width = (high[0] - low[0]) / size[0];
  framing.height = (high[1] - low[1]) / size[1];
  return framing;
}

// Meshes and clouds without a sensor pose open seen from their widest side (the view direction
// along the smallest principal axis) and fill 70 % or more of the frame's width or height.
TEST_F(Viewer, TheObjectFillsTheFrameSeenFromItsWidestSide) {
  for (const char* file : {"meshes/cow.off", "meshes/igea.ply", "meshes/rocker-arm.off",
                           "clouds/terrain_CSite1_red2-utm.pcd"}) {
    SCOPED_TRACE(file);
    auto model = open(sharedData(file));
    ViewerWindow window(*model, 400, 300);
    screenshot(window, "framed");
    const Framing framing = framingOf(window, model->inputPositions());
    std::printf("%s fills %.0f %% of the width, %.0f %% of the height\n", file, 100 * framing.width,
                100 * framing.height);
    EXPECT_TRUE(framing.inside);
    EXPECT_GE(std::max(framing.width, framing.height), 0.7);
    // The camera looks along the smallest principal axis of the points.
    const Eigen::Matrix3Xd& x = model->inputPositions();
    const Eigen::Vector3d centre = x.rowwise().mean();
    const Eigen::Matrix3d covariance = (x.colwise() - centre) * (x.colwise() - centre).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> axes(covariance);
    double direction[3];
    window.sceneRenderer()->GetActiveCamera()->GetDirectionOfProjection(direction);
    EXPECT_GT(std::abs(Eigen::Vector3d(direction).normalized().dot(axes.eigenvectors().col(0))),
              0.999);
  }
  // A cloud without a sensor pose and with a NaN point is framed by its finite points.
  const std::string with_nan = dir_ + "/with_nan.pcd";
  {
    std::ofstream out(with_nan);
    out << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 401\nHEIGHT 1\n"
           "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 401\nDATA ascii\nnan nan nan\n";
    for (int i = 0; i < 400; ++i)
      out << (i % 20) * 0.1 << " " << (i / 20) * 0.05 << " " << 0.01 * (i % 7) << "\n";
  }
  auto cloud = open(with_nan);
  ViewerWindow cloud_window(*cloud, 400, 300);
  const Image cloud_picture = screenshot(cloud_window, "with_nan");
  const Framing cloud_framing = framingOf(cloud_window, cloud->inputPositions());
  EXPECT_TRUE(cloud_framing.inside);
  EXPECT_GE(std::max(cloud_framing.width, cloud_framing.height), 0.7);
  EXPECT_GT(cloud_picture.objectShare(), 0.01);  // 400 points, drawn where the frame is
  // Terrain in UTM coordinates: a map seen from above, north up.
  auto terrain = open(sharedData("clouds/terrain_CSite1_red2-utm.pcd"));
  ViewerWindow window(*terrain, 400, 300);
  screenshot(window, "terrain");
  double direction[3], up[3];
  window.sceneRenderer()->GetActiveCamera()->GetDirectionOfProjection(direction);
  window.sceneRenderer()->GetActiveCamera()->GetViewUp(up);
  EXPECT_LT(direction[2], -0.9);
  EXPECT_GT(up[1], 0.9);
}

// An organized frame, and a cloud with a VIEWPOINT, open as their sensor saw them (pcl_viewer's
// convention: looking along the sensor's z, its -y up), the object filling the frame.
TEST_F(Viewer, CloudsWithASensorPoseAreSeenFromTheSensor) {
  const auto expectFromSensor = [&](const std::string& file, const Eigen::Vector3d& forward,
                                    const Eigen::Vector3d& up) {
    SCOPED_TRACE(file);
    auto model = open(file);
    ViewerWindow window(*model, 400, 300);
    screenshot(window, "sensor");
    double direction[3], view_up[3];
    window.sceneRenderer()->GetActiveCamera()->GetDirectionOfProjection(direction);
    window.sceneRenderer()->GetActiveCamera()->GetViewUp(view_up);
    EXPECT_GT(Eigen::Vector3d(direction).normalized().dot(forward), 0.999);
    EXPECT_GT(Eigen::Vector3d(view_up).normalized().dot(up), 0.999);
    const Framing framing = framingOf(window, model->inputPositions());
    EXPECT_TRUE(framing.inside);
    EXPECT_GE(std::max(framing.width, framing.height), 0.7);
  };
  // office1.pcd: VIEWPOINT 0 0 0 0 1 0 0, turned half round about x: looking along -z, +y up.
  expectFromSensor(sharedData("clouds/office1.pcd"), -Eigen::Vector3d::UnitZ(),
                   Eigen::Vector3d::UnitY());
  // A wall of points seen from a sensor at (0, 0, 5) turned half round about y (VIEWPOINT's
  // quaternion w x y z = 0 0 1 0): it looks along -z, with -y up.
  const std::string file = dir_ + "/posed.pcd";
  {
    std::ofstream out(file);
    out << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 400\nHEIGHT 1\n"
           "VIEWPOINT 0 0 5 0 0 1 0\nPOINTS 400\nDATA ascii\n";
    for (int i = 0; i < 400; ++i) out << (i % 20) * 0.1 << " " << (i / 20) * 0.05 << " 0\n";
  }
  expectFromSensor(file, -Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitY());
}

// The colour bar's labels are numbers as people write them: -123 and 0.5, not VTK's "-123." .
TEST_F(Viewer, TheColourBarLabelsHaveNoTrailingDot) {
  auto model = open(sharedData("meshes/cow.off"));
  ViewerWindow window(*model, 400, 300);
  window.enqueue("field=mean");
  screenshot(window, "mean");
  vtkScalarBarActor* bar = nullptr;
  vtkActor2DCollection* actors = window.sceneRenderer()->GetActors2D();
  actors->InitTraversal();
  while (vtkActor2D* actor = actors->GetNextActor2D()) {
    if (auto* candidate = vtkScalarBarActor::SafeDownCast(actor)) bar = candidate;
  }
  ASSERT_NE(bar, nullptr);
  for (const auto& [value, text] : std::vector<std::pair<double, std::string>>{
           {-123.0, "-123"}, {0.5, "0.5"}, {2.0, "2"}, {-0.000125, "-0.000125"}}) {
    char label[64];
    std::snprintf(label, sizeof label, bar->GetLabelFormat(), value);
    EXPECT_EQ(std::string(label), text);
  }
}

TEST(HiddenFaces, OnlyClosedOutwardSurfacesQualify) {
  const SurfaceSample sphere = makeIcosphere(3);
  const int n = static_cast<int>(sphere.points.cols());
  EXPECT_TRUE(viewer::facesOutward(MeshTopology(n, sphere.triangles), sphere.points));

  Eigen::Matrix3Xi inward = sphere.triangles;
  inward.row(1).swap(inward.row(2));
  EXPECT_FALSE(viewer::facesOutward(MeshTopology(n, inward), sphere.points));

  const Eigen::Matrix3Xi open = sphere.triangles.leftCols(sphere.triangles.cols() - 1);
  EXPECT_FALSE(viewer::facesOutward(MeshTopology(n, open), sphere.points));

  // Two spheres side by side: both outward qualify; one inward does not, although the sum of
  // their volumes is positive when the inward one is the smaller.
  Eigen::Matrix3Xd two(3, 2 * n);
  two << sphere.points, (0.5 * sphere.points).colwise() + Eigen::Vector3d(3.0, 0.0, 0.0);
  Eigen::Matrix3Xi outward_pair(3, 2 * sphere.triangles.cols());
  outward_pair << sphere.triangles, sphere.triangles.array() + n;
  EXPECT_TRUE(viewer::facesOutward(MeshTopology(2 * n, outward_pair), two));
  Eigen::Matrix3Xi mixed_pair(3, 2 * sphere.triangles.cols());
  mixed_pair << sphere.triangles, inward.array() + n;
  EXPECT_FALSE(viewer::facesOutward(MeshTopology(2 * n, mixed_pair), two));

  Eigen::Matrix3Xd not_finite = sphere.points;
  not_finite(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(viewer::facesOutward(MeshTopology(n, sphere.triangles), not_finite));
}

TEST_F(Viewer, FiftyKeyPressesDuringAFitAreAllApplied) {
  auto model = open(sharedData("clouds/milk.pcd"));
  ViewerWindow window(*model, 400, 300);
  ASSERT_TRUE(window.runUntilIdle(120.0));
  window.enqueue("method=quadric");
  window.runUntilIdle(0.01);  // the quadric fit starts; the presses arrive while it runs
  ViewerState expected = window.state();
  viewer::applyAction(expected, model->capabilities(), "method=quadric");
  int during_fit = 0;
  for (int i = 0; i < 50; ++i) {  // up and down, ending a few steps above where it began
    const bool up = i % 2 == 0 || i >= 46;
    during_fit += window.computing();
    pressKey(window, up ? "bracketright" : "bracketleft", up ? ']' : '[');
    viewer::applyAction(expected, model->capabilities(), up ? "k+" : "k-");
    window.runUntilIdle(0.002);
  }
  EXPECT_GT(during_fit, 0) << "no press arrived while a fit was running";
  ASSERT_TRUE(window.runUntilIdle(300.0));
  EXPECT_FALSE(window.computing());
  EXPECT_EQ(window.state(), expected);
  EXPECT_EQ(window.state().k, expected.k);
  EXPECT_TRUE(window.errors().empty());
  EXPECT_EQ(window.frame().normals->cols(), model->capabilities().points);
}

TEST_F(Viewer, RobustNormalsAreTheLibrarys) {
  auto model = open(sharedData("clouds/milk.pcd"));
  ViewerWindow window(*model, 200, 200);
  window.enqueue("method=robust");
  window.enqueue("k=40");
  ASSERT_TRUE(window.runUntilIdle(120.0));
  EXPECT_TRUE(window.errors().empty());
  LocalFitOptions options;
  options.method = LocalFitMethod::Robust;
  options.k = 40;
  options.viewpoint = model->sensorPose().origin;
  const LocalFitResult library =
      fitLocalSurfaces(makeLocalCloud(model->inputPositions()), nullptr, options);
  EXPECT_EQ(*window.frame().normals, tools::normalsOf(library.normals));
}

TEST(ViewerActions, NeighboursByTheirNamesAndTheFormerSpellings) {
  const viewer::InputCapabilities mesh{true, 100, {}};
  ViewerState state = viewer::initialState(mesh);
  for (const auto& [value, expected] : {std::pair{"kdtree", NeighbourhoodKind::KdTree},
                                        {"rings", NeighbourhoodKind::MeshRings},
                                        {"knn", NeighbourhoodKind::KdTree},
                                        {"bfs", NeighbourhoodKind::MeshRings}}) {
    viewer::applyAction(state, mesh, std::string("neighbours=") + value);
    EXPECT_EQ(state.neighbours, expected) << value;
  }
}

TEST(ViewerActions, RefuseWhatTheInputCannotDoAndClampK) {
  viewer::InputCapabilities cloud{false, 100, {"intensity"}};
  ViewerState state = viewer::initialState(cloud);
  EXPECT_EQ(state.method, viewer::NormalMethod::PCA);
  EXPECT_THROW(viewer::applyAction(state, cloud, "method=area"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "neighbours=rings"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "neighbours=bfs"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "neighbours=octree"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "smooth=implicit"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "field=compare"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "k=two"), std::invalid_argument);
  EXPECT_THROW(viewer::applyAction(state, cloud, "colour=red"), std::invalid_argument);
  viewer::applyAction(state, cloud, "field=intensity");
  EXPECT_EQ(state.field, "intensity");
  EXPECT_THROW(viewer::applyAction(state, cloud, "reference=area"), std::invalid_argument);
  viewer::applyAction(state, cloud, "reference=quadric");
  EXPECT_EQ(state.reference, viewer::NormalMethod::Quadric);
  viewer::applyAction(state, cloud, "reference=auto");
  EXPECT_FALSE(state.reference.has_value());
  EXPECT_FALSE(viewer::applyAction(state, cloud, "k=5000").empty());  // clamped, and said so
  EXPECT_EQ(state.k, 99);
  viewer::applyAction(state, cloud, "method+");
  EXPECT_EQ(state.method, viewer::NormalMethod::Quadric);
  viewer::applyAction(state, cloud, "method+");
  EXPECT_EQ(state.method, viewer::NormalMethod::Robust);
  viewer::applyAction(state, cloud, "method+");  // mesh methods are skipped on a cloud
  EXPECT_EQ(state.method, viewer::NormalMethod::PCA);
  EXPECT_EQ(viewer::splitActions("k=3 # comment\n field=none"),
            (std::vector<std::string>{"k=3", "field=none"}));
}

// The window lists every method; a cloud's are the fitted ones, the mesh methods greyed out.
TEST(ViewerActions, EveryMethodIsListedAndACloudOffersOnlyTheFittedOnes) {
  using viewer::NormalMethod;
  const auto offered = [](bool is_mesh) {
    std::vector<NormalMethod> methods;
    for (const auto& [method, available] : viewer::methodsOffered({is_mesh, 100, {}})) {
      if (available) methods.push_back(method);
    }
    return methods;
  };
  EXPECT_EQ(viewer::methodsOffered({false, 100, {}}).size(), 7u);
  EXPECT_EQ(offered(false), (std::vector<NormalMethod>{NormalMethod::PCA, NormalMethod::Quadric,
                                                       NormalMethod::Robust}));
  EXPECT_EQ(offered(true).size(), 7u);
}

TEST_F(Viewer, TheAngleFieldComparesWithTheChosenReference) {
  auto model = open(sharedData("meshes/cow.off"));
  ViewerState state = viewer::initialState(model->capabilities());  // area normals
  viewer::applyAction(state, model->capabilities(), "field=angle");
  viewer::applyAction(state, model->capabilities(), "reference=area");
  const viewer::Frame same = model->compute(state);
  EXPECT_NE(same.field_label.find("area"), std::string::npos);
  EXPECT_LT(same.field.maxCoeff(), 1e-5);  // area against area: nothing (acos rounding only)
  viewer::applyAction(state, model->capabilities(), "reference=uniform");
  const viewer::Frame other = model->compute(state);
  EXPECT_NE(other.field_label.find("uniform"), std::string::npos);
  EXPECT_GT(other.field.mean(), 0.5);  // degrees: uniform and area weights differ on the cow
}

TEST_F(Viewer, EverySharedFileOpensAndRenders) {
  for (const char* name :
       {"meshes/bumpy.off", "meshes/bun045_rangegrid_tri.ply", "meshes/bun_zipper.ply",
        "meshes/bun_zipper_res3.ply", "meshes/bun_zipper_res4.ply", "meshes/bunny.off",
        "meshes/cow.off", "meshes/horse.ply", "meshes/igea.ply", "meshes/rocker-arm.off",
        "meshes/tum_rabbit.vtk", "clouds/bun0.pcd", "clouds/milk.pcd", "clouds/office1.pcd",
        "clouds/rs1.pcd", "clouds/table_scene_mug_stereo_textured.pcd",
        "clouds/terrain_CSite1_red2-utm.pcd", "clouds/tutorials_room_scan1.pcd",
        "range/bun000.ply"}) {
    SCOPED_TRACE(name);
    const std::string png = dir_ + "/" + std::filesystem::path(name).stem().string() + ".png";
    const ToolRun run = runTool(PCL_DDG_VIEWER_TOOL, "'" + sharedData(name) + "' -screenshot '" +
                                                         png + "' -size 320x240 -do field=mean");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const Image image = readPng(png);
    EXPECT_EQ(image.width, 320);
    EXPECT_GT(image.objectShare(), 0.01);
  }
}

// The interactive loop of the tool itself, driven by real X key events: 'v' colours by mean
// curvature, F12 writes that picture, 'q' ends the loop and the tool exits cleanly (the loop pumps
// X events itself rather than through PCLVisualizer::spinOnce, and closing the window closes the
// connection it pumps). The deadlines are for a hang, not a speed limit.
TEST_F(Viewer, RealKeyPressesDriveTheInteractiveLoopAndQEndsIt) {
  // A file name of its own: the window is found by its title, "pcl_ddg_viewer: <file name>".
  const std::string input = dir_ + "/cow_by_keys.off";
  std::filesystem::copy_file(sharedData("meshes/cow.off"), input);
  const std::string title = "pcl_ddg_viewer: cow_by_keys.off";
  auto viewer = std::async(std::launch::async, [&] {
    return runTool("cd '" + dir_ + "' && " + PCL_DDG_VIEWER_TOOL, "'" + input + "' -size 480x360");
  });
  const std::string picture = dir_ + "/pcl_ddg_viewer_001.png";
  EXPECT_TRUE(sendKeys(title, {"v", "F12"}, std::chrono::minutes(1)));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!std::filesystem::exists(picture) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(sendKeys(title, {"q"}, std::chrono::minutes(1)));
  if (viewer.wait_for(std::chrono::minutes(1)) != std::future_status::ready) {
    // Not left running: the future would wait for it forever.
    ASSERT_EQ(std::system("pkill -f cow_by_keys.off"), 0);
    FAIL() << "q did not end the viewer";
  }
  const ToolRun run = viewer.get();
  EXPECT_EQ(run.exit_code, 0) << run.err;
  int colourful = 0;
  readPng(picture).forObject(
      [&](const unsigned char* p) { colourful += std::abs(p[0] - p[2]) > 40; });
  EXPECT_GT(colourful, 500);
}

TEST_F(Viewer, ErrorsAreOneLine) {
  writeText(dir_ + "/broken.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n");
  for (const std::string& arguments :
       {"'" + dir_ + "/broken.ply' -screenshot '" + dir_ + "/x.png'",
        "'" + sharedData("meshes/cow.off") + "' -do method=nonsense -screenshot '" + dir_ +
            "/x.png'",
        "'" + sharedData("clouds/bun0.pcd") + "' -do method=area -screenshot '" + dir_ + "/x.png'",
        "'" + sharedData("meshes/cow.off") + "' -size 10x10 -screenshot '" + dir_ + "/x.png'"}) {
    const ToolRun run = runTool(PCL_DDG_VIEWER_TOOL, arguments);
    EXPECT_NE(run.exit_code, 0) << arguments;
    // Exactly one error line (a usage error is followed by the syntax, as in every tool).
    const std::size_t error = run.err.find("pcl_ddg_viewer: error: ");
    ASSERT_NE(error, std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("error", error + 23), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ + "/x.png"));
  }
  const ToolRun headless = runTool("env -u DISPLAY " + std::string(PCL_DDG_VIEWER_TOOL),
                                   "'" + sharedData("meshes/cow.off") + "'");
  EXPECT_EQ(headless.exit_code, 1);
  EXPECT_EQ(headless.err,
            "pcl_ddg_viewer: error: no display: DISPLAY is not set (run it on a "
            "desktop, or headless under xvfb-run)\n");
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
