#pragma once
// Runs a built tool as a child process and captures what it prints.
#include <string>

namespace pcl_ddg {
namespace test {

struct ToolRun {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/** Runs "binary arguments" through the shell. */
ToolRun runTool(const std::string& binary, const std::string& arguments);

}  // namespace test
}  // namespace pcl_ddg
