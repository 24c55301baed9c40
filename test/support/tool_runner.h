#pragma once
// Runs a built tool as a child process and captures what it prints.
#include <cstdint>
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

/** What a tool's own process measured of itself (PCL_DDG_PEAK_MEMORY_FILE): its peak resident
 *  memory in bytes, -1 if it crashed or wrote none. The parent's getrusage cannot tell this:
 *  Linux carries ru_maxrss across exec, so a forked child starts at the test runner's size. */
struct MeasuredRun {
  int exit_code = -1;
  std::int64_t peak_bytes = -1;
};

/** Runs "binary arguments" (output discarded) with an address-space limit of address_limit bytes
 *  (0: none), and returns its own measurement. */
MeasuredRun runToolMeasured(const std::string& binary, const std::string& arguments,
                            std::uint64_t address_limit = 0);

}  // namespace test
}  // namespace pcl_ddg
