#pragma once
// The viewer's window, on pcl::visualization::PCLVisualizer: draws a Frame (surface or points
// coloured by the field, normal glyphs, overlay text, colour bar) and turns key presses into
// actions. Actions wait in a queue; whenever no computation runs, all queued actions are applied
// to the state at once (50 presses of ']' become one fit for the final k) and the frame is
// computed on a worker thread, so the window keeps drawing and no press is lost.
#include <pcl/visualization/pcl_visualizer.h>
#include <vtkSmartPointer.h>

#include <chrono>
#include <deque>
#include <future>
#include <memory>
#include <string>

#include "viewer/viewer_model.h"

class vtkActor;
class vtkCellArray;
class vtkPoints;
class vtkProperty;
class vtkScalarBarActor;
class vtkTextActor;
class vtkRenderWindowInteractor;
class vtkRenderer;

namespace pcl_ddg {
namespace viewer {

class ViewerWindow {
 public:
  /** Opens the window (the caller has checked that a display exists). */
  ViewerWindow(ViewerModel& model, int width, int height);
  ~ViewerWindow();

  /** Queues an action, as a key press does. */
  void enqueue(const std::string& action);
  /** The interactive loop, until the window is closed. */
  void run();
  /** Spins until every queued action is computed and drawn; false on timeout. */
  bool runUntilIdle(double timeout_seconds);
  void saveScreenshot(const std::string& path);

  /** The state of the frame on screen. */
  const ViewerState& state() const { return shown_.state; }
  const Frame& frame() const { return shown_; }
  /** Whether a computation (a fit, a smoothing step) is running in the background. */
  bool computing() const { return computing_.valid(); }
  /** Messages of refused actions, in order. */
  const std::vector<std::string>& errors() const { return errors_; }
  vtkRenderWindowInteractor* interactor();
  pcl::visualization::PCLVisualizer& visualizer() { return *visualizer_; }
  /** Whether back faces may be left out where none can be seen (the default); false draws all. */
  void setHiddenFaceCulling(bool allowed);
  /** Whether the last render left out the back faces. */
  bool culledBackFaces() const;
  /** The visualizer's renderer: the scene's camera and actors (viewer_scene.cpp). */
  vtkRenderer* sceneRenderer() const;

 private:
  void onKey(const pcl::visualization::KeyboardEvent& event);
  /** Dispatches the pending X events and VTK timers, waiting at most kEventWaitMs for one. */
  void processEvents();
  /** Collects a finished computation and starts the next one; true when idle afterwards. */
  bool step();
  void draw(const Frame& frame);
  void placeCamera();
  /** One render when something changed since the last (the only place that renders). */
  void renderIfChanged();
  void drawSurface(const Frame& frame);
  /** The surface actor drawing these normals, made if none does; it becomes the one shown. */
  vtkActor& showSurface(const std::shared_ptr<const Eigen::Matrix3Xd>& normals);
  /** Before every render (also the interactor's): cull back faces where none can be seen. */
  void cullHiddenFaces();
  void drawNormals(const Frame& frame);
  void drawOverlay(const Frame& frame, const std::string& status);
  void addMethodLabels(int height);
  void takeScreenshot();

  ViewerModel& model_;
  std::unique_ptr<pcl::visualization::PCLVisualizer> visualizer_;
  ViewerState pending_;  ///< the state after every action queued so far
  std::deque<std::string> queue_;
  std::future<Frame> computing_;
  std::chrono::steady_clock::time_point computing_since_;
  bool computing_shown_ = false;
  bool needs_render_ = false;
  Frame shown_;
  bool drawn_once_ = false;
  std::vector<std::string> errors_;
  std::vector<std::string> notes_;  ///< of actions since the last frame (k clamped, refusals)
  /** A surface actor per normals recently shown, the one on screen first: switching back to
   *  normals still here draws buffers VTK already has (a changed normals array makes VTK rebuild
   *  its vertex buffers, a quarter of a software render of a million vertices). All share the
   *  points, the cells and one property. */
  struct SurfaceActor {
    std::shared_ptr<const Eigen::Matrix3Xd> normals;
    vtkSmartPointer<vtkActor> actor;
  };
  std::vector<SurfaceActor> surfaces_;
  vtkSmartPointer<vtkProperty> surface_property_;
  vtkSmartPointer<vtkActor> glyphs_;
  bool cull_allowed_ = true;
  bool faces_outward_ = false;  ///< of the positions shown (see hidden_faces.h)
  unsigned long cull_observer_ = 0;
  vtkSmartPointer<vtkTextActor> text_;
  /** The normal methods along the top, the current one bright, those the input lacks greyed. */
  struct MethodLabel {
    NormalMethod method;
    bool offered;
    vtkSmartPointer<vtkTextActor> actor;
  };
  std::vector<MethodLabel> method_labels_;
  vtkSmartPointer<vtkScalarBarActor> color_bar_;
  vtkSmartPointer<vtkCellArray> cells_;  ///< triangles or vertices: the same in every frame
  vtkSmartPointer<vtkPoints> points_;    ///< of points_owner_
  std::shared_ptr<const Eigen::Matrix3Xd> points_owner_;  ///< the positions shown
};

/** One line saying why no window can open (no DISPLAY, or an X server that does not answer), or
 *  "" when a display is there. */
std::string displayProblem();

}  // namespace viewer
}  // namespace pcl_ddg
