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

#include "viewer/hidden_faces.h"

namespace pcl_ddg {
namespace viewer {
namespace {

// How long one turn of the event loop may wait for an X event: the bound on how late a frame
// finished by the worker thread is drawn.
constexpr int kEventWaitMs = 10;

}  // namespace

std::string displayProblem() {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    return "no display: DISPLAY is not set (run it on a desktop, or headless under xvfb-run)";
  }
  Display* connection = XOpenDisplay(nullptr);
  if (connection == nullptr) {
    return std::string("cannot open display '") + display + "' (is the X server running?)";
  }
  XCloseDisplay(connection);
  return "";
}

ViewerWindow::ViewerWindow(ViewerModel& model, int width, int height)
    : model_(model), pending_(initialState(model.capabilities())) {
  const std::string& path = model_.path();
  visualizer_ = std::make_unique<pcl::visualization::PCLVisualizer>(
      "pcl_ddg_viewer: " + path.substr(path.find_last_of('/') + 1));
  visualizer_->setSize(width, height);
  visualizer_->setBackgroundColor(0.12, 0.12, 0.14);
  visualizer_->setShowFPS(false);
  // Edges smoothed by FXAA, one pass over the finished image, instead of VTK's default 4x
  // multisampling: without a GPU (Mesa's llvmpipe, as under Xvfb or over a remote display)
  // multisampling made every frame of a 1.15M-vertex mesh 3.1x slower (582 against 188 ms), and
  // FXAA costs nothing measurable.
  visualizer_->getRenderWindow()->SetMultiSamples(0);
  sceneRenderer()->UseFXAAOn();
  visualizer_->registerKeyboardCallback(
      [this](const pcl::visualization::KeyboardEvent& event) { onKey(event); });
  text_ = vtkSmartPointer<vtkTextActor>::New();
  text_->GetTextProperty()->SetFontSize(14);
  text_->GetTextProperty()->SetColor(0.95, 0.95, 0.95);
  text_->SetDisplayPosition(10, 10);
  sceneRenderer()->AddActor2D(text_);
  addMethodLabels(height);
  surface_property_ = vtkSmartPointer<vtkProperty>::New();
  cull_observer_ =
      sceneRenderer()->AddObserver(vtkCommand::StartEvent, this, &ViewerWindow::cullHiddenFaces);
}

ViewerWindow::~ViewerWindow() {
  // Not visualizer_->close(): PCL's X interactor then asks a closed display for an atom (crash).
  if (computing_.valid()) computing_.wait();
  sceneRenderer()->RemoveObserver(cull_observer_);
}

vtkRenderWindowInteractor* ViewerWindow::interactor() {
  return visualizer_->getRenderWindow()->GetInteractor();
}

void ViewerWindow::enqueue(const std::string& action) {
  queue_.push_back(action);
}

void ViewerWindow::onKey(const pcl::visualization::KeyboardEvent& event) {
  if (!event.keyDown()) return;
  if (event.getKeySym() == "h") {
    std::cout << "pcl_ddg_viewer keys:\n" << keyHelp() << std::flush;
    return;
  }
  const std::string action = actionForKey(event.getKeySym());
  if (!action.empty()) enqueue(action);
}

bool ViewerWindow::step() {
  if (computing_.valid()) {
    if (computing_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
    try {
      Frame frame = computing_.get();
      // Refused smoothing steps leave the state too, so later actions build on what is shown.
      if (frame.step_refused) pending_.steps = frame.state.steps;
      shown_ = std::move(frame);
      draw(shown_);
    } catch (const std::exception& e) {
      if (!drawn_once_) throw;  // nothing to show: the tool's one-line error
      errors_.push_back(e.what());
      notes_.push_back(std::string("computation failed: ") + e.what());
      pending_ = shown_.state;
      drawOverlay(shown_, "");
    }
    notes_.clear();
  }
  while (!queue_.empty()) {
    const std::string action = queue_.front();
    if (action == "screenshot") {
      // Of what is queued before it, drawn.
      if (!drawn_once_ || pending_ != shown_.state) break;
      applyAction(pending_, model_.capabilities(), action);
      shown_.state.screenshots = pending_.screenshots;
      takeScreenshot();
      queue_.pop_front();
      continue;
    }
    queue_.pop_front();
    try {
      const std::string note = applyAction(pending_, model_.capabilities(), action);
      if (!note.empty()) notes_.push_back(note);
    } catch (const std::invalid_argument& e) {
      errors_.push_back(e.what());
      notes_.push_back(e.what());
      std::cerr << "pcl_ddg_viewer: " << e.what() << "\n";
    }
  }
  if (drawn_once_ && pending_ == shown_.state) {
    if (!notes_.empty()) drawOverlay(shown_, "");
    return queue_.empty();
  }
  const ViewerState state = pending_;
  computing_ = std::async(std::launch::async, [this, state] { return model_.compute(state); });
  computing_since_ = std::chrono::steady_clock::now();
  computing_shown_ = false;
  return false;
}

void ViewerWindow::renderIfChanged() {
  // "computing ..." only for work that takes a while: with software OpenGL a redraw of a large
  // mesh costs as much as the computation.
  constexpr auto kShowComputingAfter = std::chrono::milliseconds(300);
  if (computing_.valid() && !computing_shown_ && drawn_once_ &&
      std::chrono::steady_clock::now() - computing_since_ > kShowComputingAfter) {
    drawOverlay(shown_, "computing ...");
    computing_shown_ = true;
  }
  if (!needs_render_) return;
  visualizer_->getRenderWindow()->Render();
  needs_render_ = false;
}

void ViewerWindow::takeScreenshot() {
  char name[64];
  std::snprintf(name, sizeof name, "pcl_ddg_viewer_%03d.png", shown_.state.screenshots);
  saveScreenshot(name);
  std::cout << "pcl_ddg_viewer: wrote " << name << "\n";
}

void ViewerWindow::processEvents() {
  // Not PCLVisualizer::spinOnce(), which is VTK 9.1's ProcessEvents(): with no X event pending
  // that waits in select() for one, or for a VTK timer, up to a second, so a frame finished by the
  // worker waited that long to be drawn (a cached switch took 2.7 s, mostly waiting). A VTK timer
  // cannot bound the wait: PCL's interactor style renders on every timer event. So the wait is
  // ours, on the X connection, and VTK dispatches only what is pending.
  // The connection is looked up afresh each time: closing the window ('q') closes it.
  const auto display = [this] {
    return static_cast<Display*>(visualizer_->getRenderWindow()->GetGenericDisplayId());
  };
  if (display() == nullptr) return;
  if (XPending(display()) == 0) {
    pollfd connection{ConnectionNumber(display()), POLLIN, 0};
    // While the worker computes, look again within a millisecond: its frame is drawn sooner.
    poll(&connection, 1, computing_.valid() ? 1 : kEventWaitMs);
  }
  while (!visualizer_->wasStopped() && display() != nullptr && XPending(display()) != 0) {
    interactor()->ProcessEvents();
  }
}

void ViewerWindow::run() {
  while (!visualizer_->wasStopped()) {
    processEvents();
    step();
    renderIfChanged();
  }
}

bool ViewerWindow::runUntilIdle(double timeout_seconds) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    processEvents();
    const bool idle = step() && !computing_.valid() && queue_.empty();
    renderIfChanged();
    if (idle) return true;
  }
  return false;
}

void ViewerWindow::saveScreenshot(const std::string& path) {
  renderIfChanged();
  visualizer_->saveScreenshot(path);
}

}  // namespace viewer
}  // namespace pcl_ddg
