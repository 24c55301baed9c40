#pragma once
// The options that pick an operator's variant: the vertex areas (-area, -mass) and the implicit
// solver (-solver).
#include <string>

#include "common/tool_common.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/surface/implicit_solver.h"

namespace pcl_ddg {
namespace tools {

/** -area mixed|voronoi|barycentric (the vertex areas, the mass matrix's diagonal: chooseMassType),
 *  default mixed; pcl_ddg_smooth's former -mass is read as -area (both given: UsageError). */
MassType vertexAreaArgument(const ToolArguments& args);

/** -solver auto|cholmod|ldlt|cg (chooseSolver), default auto. */
SolverChoice solverArgument(const ToolArguments& args);

}  // namespace tools
}  // namespace pcl_ddg
