// pcl_ddg_viewer: a scan in PCL's visualizer, with keys that switch the normal method, k, the
// neighbourhood and the colour field, and smooth the mesh step by step; -do applies the same
// actions from the command line and -screenshot writes the picture and exits.
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/tool_common.h"
#include "common/tool_input.h"
#include "viewer/viewer_window.h"

namespace {

constexpr const char* kName = "pcl_ddg_viewer";
constexpr const char* kDescription =
    "Shows a mesh (shaded) or a point cloud with its normals and curvatures: keys switch the\n"
    "normal method, k, the neighbourhood and the colour field, and smooth the mesh step by step.";

std::string syntax() {
  return "input.{ply,obj,off,stl,vtk,pcd}\n"
         "         [-do \"actions\"] [-commands file (actions, one or more per line, # comments)]\n"
         "         [-screenshot out.png (draw, write the picture, exit)] [-size WxH (default "
         "1024x768)]\n"
         "Actions (also what the keys send):\n"
         "  method=uniform|area|angle|mean_curvature|pca|quadric|robust  k=N  "
         "neighbours=rings|kdtree\n"
         "  field=none|rgb|mean|gauss|k1|k2|angle|compare|<property of the file> (rgb: its "
         "colours)\n"
         "  reference=auto|<method> (what field=angle compares with)\n"
         "  smooth=explicit|implicit[:t]|taubin (t: step in h^2, umbrella: no unit)  step=t\n"
         "  weights=cotan|uniform|umbrella\n"
         "  frozen=on|off  undo  normals=on|off  shading=flat|smooth  screenshot\n"
         "Keys:\n" +
         pcl_ddg::viewer::keyHelp();
}

std::pair<int, int> sizeArgument(const pcl_ddg::tools::ToolArguments& args) {
  const std::string text = args.text("size", "1024x768");
  int width = 0, height = 0;
  char x = 0, rest = 0;
  std::istringstream in(text);
  if (!(in >> width >> x >> height) || x != 'x' || (in >> rest) || width < 64 || height < 64 ||
      width > 8192 || height > 8192) {
    throw pcl_ddg::tools::UsageError("-size must be WxH, 64 to 8192 each (got '" + text + "')");
  }
  return {width, height};
}

int run(int argc, char** argv) {
  using namespace pcl_ddg;
  const tools::ToolArguments args(argc, argv, {"do", "commands", "screenshot", "size"}, {});
  if (args.positional().size() != 1) throw tools::UsageError("expected one input file");
  const auto [width, height] = sizeArgument(args);
  std::vector<std::string> actions;
  if (args.has("commands")) {
    std::ifstream file(*args.value("commands"));
    if (!file) throw std::runtime_error("cannot read the commands file " + *args.value("commands"));
    std::stringstream text;
    text << file.rdbuf();
    actions = viewer::splitActions(text.str());
  }
  for (const std::string& action : viewer::splitActions(args.text("do", ""))) {
    actions.push_back(action);
  }
  if (args.has("screenshot") && fileExtension(*args.value("screenshot")) != "png") {
    throw tools::UsageError("-screenshot writes a .png");
  }
  if (args.has("screenshot"))
    tools::checkOutputFile(*args.value("screenshot"), {args.positional().front()});
  // Before the file is read: a window that cannot open should not cost a load first.
  if (const std::string problem = viewer::displayProblem(); !problem.empty()) {
    throw std::runtime_error(problem);
  }

  viewer::ViewerModel model(tools::ToolInput(args.positional().front(), kName),
                            args.positional().front());
  // -do actions are checked before the window opens, so that a typo is the tool's error line.
  viewer::ViewerState check = viewer::initialState(model.capabilities());
  for (const std::string& action : actions) {
    try {
      viewer::applyAction(check, model.capabilities(), action);
    } catch (const std::invalid_argument& e) {
      throw tools::UsageError(std::string("-do ") + e.what());
    }
  }

  viewer::ViewerWindow window(model, width, height);
  for (const std::string& action : actions) window.enqueue(action);
  if (!args.has("screenshot")) {
    std::cout << "pcl_ddg_viewer keys (h prints them again):\n" << viewer::keyHelp() << std::flush;
    window.run();
    return 0;
  }
  tools::Timer timer("Computing and drawing");
  if (!window.runUntilIdle(600.0)) throw std::runtime_error("timed out drawing the first frame");
  timer.done(static_cast<std::size_t>(model.capabilities().points));
  for (const std::string& warning : window.frame().warnings) tools::warn(kName, warning);
  const std::string output = *args.value("screenshot");
  window.saveScreenshot(output);
  std::cerr << "> Wrote " << output << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string help = syntax();
  return pcl_ddg::tools::runTool(kName, kDescription, help.c_str(),
                                 [&] { return run(argc, argv); });
}
