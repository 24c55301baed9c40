#include "common/operator_options.h"

namespace pcl_ddg {
namespace tools {

MassType vertexAreaArgument(const ToolArguments& args) {
  if (args.has("area") && args.has("mass")) throw UsageError("-mass is the former name of -area");
  const std::string option = args.has("mass") ? "mass" : "area";
  return usage(
      [&] { return chooseMassType(args.value(option).value_or("mixed"), option, kToolStyle); });
}

SolverChoice solverArgument(const ToolArguments& args) {
  return usage([&] { return chooseSolver(args.value("solver").value_or("auto"), kToolStyle); });
}

}  // namespace tools
}  // namespace pcl_ddg
