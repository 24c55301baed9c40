// The window's VTK scene: the surface and point actors, normals, colour bar, overlay and camera,
// drawn from a Frame. The event loop that decides when to draw is in viewer_window.cpp.
#include "viewer/viewer_window.h"

#include <X11/Xlib.h>
#include <poll.h>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkFloatArray.h>
#include <vtkLookupTable.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "pcl_ddg/features/normal_orientation.h"
#include "viewer/hidden_faces.h"

namespace pcl_ddg {
namespace viewer {
namespace {

// The colour bar's table: the frame's colour map sampled at 256 values across its range.
vtkSmartPointer<vtkLookupTable> lookupTable(const Frame& frame) {
  constexpr int kColors = 256;
  Eigen::VectorXd ramp(kColors);
  for (int i = 0; i < kColors; ++i)
    ramp[i] = frame.range.low + (frame.range.high - frame.range.low) * i / (kColors - 1.0);
  // The ramp already spans the frame's range: colorize() must take its ends (0th and 100th
  // percentiles), not its default 2nd and 98th.
  ColorScale scale;
  scale.low_percentile = 0.0;
  scale.high_percentile = 100.0;
  const VertexColors colors = colorize(ramp, frame.color_map, scale);
  auto table = vtkSmartPointer<vtkLookupTable>::New();
  table->SetNumberOfTableValues(kColors);
  table->SetRange(frame.range.low, frame.range.high);
  for (int i = 0; i < kColors; ++i) {
    table->SetTableValue(i, colors(0, i) / 255.0, colors(1, i) / 255.0, colors(2, i) / 255.0, 1.0);
  }
  table->Build();
  return table;
}

std::string describe(const ViewerState& s, bool is_mesh) {
  std::ostringstream out;
  out << "normals: " << methodName(s.method);
  if (!isMeshMethod(s.method)) {
    out << ", k = " << s.k << ", "
        << (s.neighbours == NeighbourhoodKind::MeshRings ? "mesh rings" : "kd-tree");
  }
  out << "   field: " << s.field;
  if (is_mesh) {
    int explicit_steps = 0;
    for (const SmoothingStep& step : s.steps)
      explicit_steps += step.method != SmoothingScheme::Implicit;
    const bool umbrella = s.weights == SmoothingWeights::Umbrella;
    out << "\nsmoothing: " << s.steps.size() << " steps (" << explicit_steps
        << " explicit or Taubin), next " << s.time_step << (umbrella ? "" : " h^2") << ", "
        << (umbrella                                 ? "umbrella"
            : s.weights == SmoothingWeights::Uniform ? "uniform"
                                                     : "cotan")
        << " weights " << (s.frozen ? "frozen" : "rebuilt");
  }
  return out.str();
}

}  // namespace

vtkRenderer* ViewerWindow::sceneRenderer() const {
  return visualizer_->getRendererCollection()->GetFirstRenderer();
}

void ViewerWindow::addMethodLabels(int height) {
  vtkRenderer* renderer = sceneRenderer();
  double x = 10;
  for (const auto& [method, offered] : methodsOffered(model_.capabilities())) {
    auto label = vtkSmartPointer<vtkTextActor>::New();
    label->SetInput(methodName(method));
    label->GetTextProperty()->SetFontSize(13);
    label->GetTextProperty()->SetVerticalJustificationToTop();
    label->SetDisplayPosition(static_cast<int>(x), height - 8);
    renderer->AddActor2D(label);
    double box[4];
    label->GetBoundingBox(renderer, box);
    x += box[1] - box[0] + 12;
    method_labels_.push_back({method, offered, label});
  }
}

void ViewerWindow::draw(const Frame& frame) {
  drawSurface(frame);
  drawNormals(frame);
  vtkRenderer* renderer = sceneRenderer();
  if (color_bar_) renderer->RemoveActor2D(color_bar_);
  color_bar_ = nullptr;
  if (!frame.field_label.empty()) {
    color_bar_ = vtkSmartPointer<vtkScalarBarActor>::New();
    color_bar_->SetLookupTable(lookupTable(frame));
    color_bar_->SetTitle(frame.field_label.c_str());
    color_bar_->SetNumberOfLabels(5);
    color_bar_->SetLabelFormat("%.3g");  // VTK's default "%-#6.3g" keeps a trailing dot: "-123."
    color_bar_->SetOrientationToHorizontal();
    color_bar_->SetPosition(0.55, 0.8);  // below the row of method names
    color_bar_->SetWidth(0.42);
    color_bar_->SetHeight(0.1);
    color_bar_->GetTitleTextProperty()->SetFontSize(12);
    color_bar_->GetLabelTextProperty()->SetFontSize(11);
    renderer->AddActor2D(color_bar_);
  }
  std::ostringstream status;
  status.precision(3);
  status << "last computation " << frame.compute_ms << " ms";
  drawOverlay(frame, status.str());
  if (!drawn_once_) placeCamera();
  drawn_once_ = true;
}

void ViewerWindow::placeCamera() {
  const SensorPose& pose = model_.sensorPose();
  const bool from_sensor =
      !model_.isMesh() && (model_.organized() || !pose.origin.isZero() ||
                           !pose.orientation.isApprox(Eigen::Quaterniond::Identity()));
  const Eigen::Matrix3Xd& positions = model_.inputPositions();
  Eigen::Vector3d forward, up, eye;
  if (from_sensor) {
    // A cloud with a sensor pose (a VIEWPOINT, or a grid) from its sensor, as pcl_viewer shows a
    // PCD: looking along the sensor's z, y down; normals face the sensor, so the lit side shows.
    forward = pose.orientation * Eigen::Vector3d::UnitZ();
    up = pose.orientation * -Eigen::Vector3d::UnitY();
    eye = pose.origin;
  } else {
    // Otherwise the side that shows the most of the object (render/mesh_render.h).
    const DefaultView view =
        defaultView(positions,
                    model_.isMesh() ? meshOrientationNormals(*model_.topology(), positions)
                                    : Eigen::Matrix3Xd(),
                    model_.geographic());
    forward = -view.front;
    up = view.up;
    eye = view.centre - forward;
  }
  const Eigen::Vector3d focal = eye + forward;
  visualizer_->setCameraPosition(eye.x(), eye.y(), eye.z(), focal.x(), focal.y(), focal.z(), up.x(),
                                 up.y(), up.z());
  vtkRenderer* renderer = sceneRenderer();
  renderer->ResetCamera();
  // ResetCamera fits the bounding sphere; zoom until the object itself fills 80 % of the frame's
  // height or width (whichever binds).
  vtkCamera* camera = renderer->GetActiveCamera();
  double position[3], focal_point[3], view_up[3];
  camera->GetPosition(position);
  camera->GetFocalPoint(focal_point);
  camera->GetViewUp(view_up);
  const Eigen::Vector3d c(focal_point), direction = (c - Eigen::Vector3d(position)).normalized();
  const Eigen::Vector3d screen_up = Eigen::Vector3d(view_up).normalized();
  const Eigen::Vector3d right = direction.cross(screen_up).normalized();
  double half_width = 0.0, half_height = 0.0;
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (!positions.col(i).allFinite()) continue;
    const Eigen::Vector3d d = positions.col(i) - c;
    half_width = std::max(half_width, std::abs(d.dot(right)));
    half_height = std::max(half_height, std::abs(d.dot(screen_up)));
  }
  const double distance = (c - Eigen::Vector3d(position)).norm();
  constexpr double kRadiansPerDegree = 3.14159265358979323846 / 180.0;
  const double visible_half_height =
      distance * std::tan(0.5 * camera->GetViewAngle() * kRadiansPerDegree);
  const int* size = visualizer_->getRenderWindow()->GetSize();
  const double aspect = size[1] > 0 ? static_cast<double>(size[0]) / size[1] : 1.0;
  const double fill =
      std::max(half_height / visible_half_height, half_width / (visible_half_height * aspect));
  if (fill > 0.0) camera->Zoom(0.8 / fill);
  renderer->ResetCameraClippingRange();
}

void ViewerWindow::drawSurface(const Frame& frame) {
  const Eigen::Matrix3Xd& positions = *frame.positions;
  const Eigen::Index n = positions.cols();
  if (points_owner_ != frame.positions) {
    points_ = vtkSmartPointer<vtkPoints>::New();
    points_->SetDataTypeToFloat();
    points_->SetNumberOfPoints(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d p = positions.col(i).allFinite() ? Eigen::Vector3d(positions.col(i))
                                                             : Eigen::Vector3d::Zero();
      points_->SetPoint(i, p.data());
    }
    points_owner_ = frame.positions;
    faces_outward_ = model_.isMesh() && facesOutward(*model_.topology(), positions);
    for (const SurfaceActor& surface : surfaces_) sceneRenderer()->RemoveActor(surface.actor);
    surfaces_.clear();
  }
  if (!cells_) {
    cells_ = vtkSmartPointer<vtkCellArray>::New();
    if (const MeshTopology* topology = model_.topology()) {
      for (int t = 0; t < topology->numTriangles(); ++t) {
        const vtkIdType corners[3] = {topology->triangles()(0, t), topology->triangles()(1, t),
                                      topology->triangles()(2, t)};
        cells_->InsertNextCell(3, corners);
      }
    } else {
      for (Eigen::Index i = 0; i < n; ++i) {
        if (!positions.col(i).allFinite()) continue;
        const vtkIdType id = i;
        cells_->InsertNextCell(1, &id);
      }
    }
  }
  vtkActor& surface = showSurface(frame.normals);
  // Colours go to VTK only when they changed: a new array is uploaded to the GPU again.
  auto colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
  colors->SetNumberOfComponents(3);
  colors->SetName("colors");
  colors->SetNumberOfTuples(n);
  // Points are drawn unlit (VTK lights them one-sided and from the camera); uncoloured, they are
  // shaded grey by how squarely their normal faces the sensor, so that the shape shows.
  const bool shade_points = !model_.isMesh() && frame.state.field == "none";
  const Eigen::Vector3d sensor_axis = model_.sensorPose().orientation * Eigen::Vector3d::UnitZ();
  // Written through the arrays' own storage: a virtual SetTypedTuple per vertex cost more than
  // the copies.
  unsigned char* rgb = colors->GetPointer(0);
  if (shade_points) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const double facing = frame.normals->col(i).allFinite()
                                ? std::abs(frame.normals->col(i).dot(sensor_axis))
                                : 0.5;
      const auto grey = static_cast<unsigned char>(60.0 + 180.0 * facing);
      rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = grey;
    }
  } else {
    std::copy_n(frame.colors.data(), 3 * n, rgb);
  }
  vtkPointData* point_data =
      vtkPolyData::SafeDownCast(surface.GetMapper()->GetInput())->GetPointData();
  vtkUnsignedCharArray* shown = vtkUnsignedCharArray::SafeDownCast(point_data->GetScalars());
  if (shown == nullptr || !std::equal(rgb, rgb + 3 * n, shown->GetPointer(0))) {
    point_data->SetScalars(colors);
  }
  if (frame.state.smooth_shading) {
    surface_property_->SetInterpolationToGouraud();
  } else {
    surface_property_->SetInterpolationToFlat();
  }
  surface_property_->SetPointSize(model_.isMesh() ? 1.0f : 2.0f);
  surface_property_->SetLighting(model_.isMesh());
}

vtkActor& ViewerWindow::showSurface(const std::shared_ptr<const Eigen::Matrix3Xd>& normals) {
  // As many as there are normal methods: cycling through all of them rebuilds nothing.
  constexpr std::size_t kSurfaceActors = 6;
  vtkRenderer* renderer = sceneRenderer();
  auto found = std::find_if(surfaces_.begin(), surfaces_.end(),
                            [&](const SurfaceActor& s) { return s.normals == normals; });
  if (found != surfaces_.end()) {
    std::rotate(surfaces_.begin(), found, found + 1);
  } else {
    const Eigen::Index n = normals->cols();
    auto array = vtkSmartPointer<vtkFloatArray>::New();
    array->SetNumberOfComponents(3);
    array->SetName("normals");
    array->SetNumberOfTuples(n);
    float* xyz = array->GetPointer(0);
    for (Eigen::Index i = 0; i < n; ++i) {
      const bool finite = normals->col(i).allFinite();
      for (int c = 0; c < 3; ++c)
        xyz[3 * i + c] = finite ? static_cast<float>((*normals)(c, i)) : 0.0f;
    }
    auto data = vtkSmartPointer<vtkPolyData>::New();
    data->SetPoints(points_);
    if (model_.isMesh()) {
      data->SetPolys(cells_);
    } else {
      data->SetVerts(cells_);
    }
    data->GetPointData()->SetNormals(array);
    auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    mapper->SetInputData(data);
    mapper->SetColorModeToDirectScalars();
    mapper->ScalarVisibilityOn();
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(mapper);
    actor->SetProperty(surface_property_);
    renderer->AddActor(actor);
    surfaces_.insert(surfaces_.begin(), {normals, actor});
    if (surfaces_.size() > kSurfaceActors) {
      renderer->RemoveActor(surfaces_.back().actor);
      surfaces_.pop_back();
    }
  }
  for (std::size_t i = 0; i < surfaces_.size(); ++i) surfaces_[i].actor->SetVisibility(i == 0);
  return *surfaces_.front().actor;
}

void ViewerWindow::cullHiddenFaces() {
  // Drawn as wireframe or points (PCL's keys w and p) or translucent, every face shows.
  const bool opaque_surface = surface_property_->GetRepresentation() == VTK_SURFACE &&
                              surface_property_->GetOpacity() >= 1.0;
  const bool cull = cull_allowed_ && faces_outward_ && opaque_surface &&
                    boxBeyondNearPlane(*sceneRenderer()->GetActiveCamera(), points_->GetBounds());
  surface_property_->SetBackfaceCulling(cull);
}

void ViewerWindow::setHiddenFaceCulling(bool allowed) {
  cull_allowed_ = allowed;
  needs_render_ = true;
}

bool ViewerWindow::culledBackFaces() const {
  return surface_property_->GetBackfaceCulling() != 0;
}

void ViewerWindow::drawNormals(const Frame& frame) {
  vtkRenderer* renderer = sceneRenderer();
  if (glyphs_) renderer->RemoveActor(glyphs_);
  glyphs_ = nullptr;
  if (!frame.state.show_normals) return;
  const Eigen::Matrix3Xd& positions = *frame.positions;
  const Eigen::Matrix3Xd& normals = *frame.normals;
  const Eigen::Index every = frame.glyph_every;  // viewer_model.cpp
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  for (Eigen::Index i = 0; i < positions.cols(); i += every) {
    if (!positions.col(i).allFinite() || !normals.col(i).allFinite()) continue;
    const Eigen::Vector3d tip = positions.col(i) + frame.glyph_length * normals.col(i);
    const vtkIdType ends[2] = {points->InsertNextPoint(positions.col(i).data()),
                               points->InsertNextPoint(tip.data())};
    lines->InsertNextCell(2, ends);
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(points);
  data->SetLines(lines);
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(data);
  glyphs_ = vtkSmartPointer<vtkActor>::New();
  glyphs_->SetMapper(mapper);
  glyphs_->GetProperty()->SetColor(1.0, 0.85, 0.2);
  glyphs_->GetProperty()->SetLighting(false);
  renderer->AddActor(glyphs_);
}

void ViewerWindow::drawOverlay(const Frame& frame, const std::string& status) {
  std::ostringstream text;
  const std::string& path = model_.path();
  text << path.substr(path.find_last_of('/') + 1) << ": " << model_.capabilities().points
       << (model_.isMesh()
               ? " vertices, " + std::to_string(model_.topology()->numTriangles()) + " triangles"
               : " points")
       << "\n"
       << describe(frame.state, model_.isMesh()) << "\n"
       << status;
  for (const std::string& warning : frame.warnings) text << "\n! " << warning;
  for (const std::string& note : notes_) text << "\n! " << note;
  text_->SetInput(text.str().c_str());
  for (const MethodLabel& label : method_labels_) {
    const bool current = label.method == frame.state.method;
    const double grey = current ? 1.0 : label.offered ? 0.7 : 0.35;
    label.actor->GetTextProperty()->SetColor(grey, grey, grey);
    label.actor->GetTextProperty()->SetBold(current);
  }
  needs_render_ = true;
}

}  // namespace viewer
}  // namespace pcl_ddg
