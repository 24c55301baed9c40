#include "common/operator_options.h"

namespace pcl_ddg {
namespace tools {

MassType vertexAreaArgument(const ToolArguments& args) {
  if (args.has("area") && args.has("mass")) throw UsageError("-mass is the former name of -area");
  const std::string option = args.has("mass") ? "mass" : "area";
  const std::string area = args.choice(option, {"mixed", "voronoi", "barycentric"}, "mixed");
  return area == "voronoi"       ? MassType::Voronoi
         : area == "barycentric" ? MassType::Barycentric
                                 : MassType::MixedVoronoi;
}

SolverChoice solverArgument(const ToolArguments& args) {
  const std::string solver = args.choice("solver", {"auto", "cholmod", "ldlt", "cg"}, "auto");
  if (solver == "cholmod") return {ImplicitSolver::Cholesky, CholeskyBackend::Cholmod};
  if (solver == "ldlt") return {ImplicitSolver::Cholesky, CholeskyBackend::SimplicialLDLT};
  if (solver == "cg") return {ImplicitSolver::ConjugateGradient, CholeskyBackend::Automatic};
  return {ImplicitSolver::Automatic, CholeskyBackend::Automatic};
}

}  // namespace tools
}  // namespace pcl_ddg
