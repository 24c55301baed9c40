#include "tool_runner.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pcl_ddg {
namespace test {

ToolRun runTool(const std::string& binary, const std::string& arguments) {
  const std::string err_path = (std::filesystem::temp_directory_path() /
                                ("pcl_ddg_tool_stderr_" + std::to_string(::getpid())))
                                   .string();
  const std::string command = binary + " " + arguments + " 2>" + err_path;
  ToolRun run;
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) run.out += buffer.data();
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(err_path);
  std::ostringstream text;
  text << err.rdbuf();
  run.err = text.str();
  std::filesystem::remove(err_path);
  return run;
}

MeasuredRun runToolMeasured(const std::string& binary, const std::string& arguments,
                            std::uint64_t address_limit) {
  const std::string peak_path = (std::filesystem::temp_directory_path() /
                                 ("pcl_ddg_tool_peak_" + std::to_string(::getpid())))
                                    .string();
  std::filesystem::remove(peak_path);
  // ulimit -v takes KiB; the limit is on the tool's own address space, after the shell's exec.
  const std::string limit =
      address_limit > 0 ? "ulimit -v " + std::to_string(address_limit / 1024) + "; " : "";
  const std::string command = limit + "PCL_DDG_PEAK_MEMORY_FILE=" + peak_path + " exec " +
                              binary + " " + arguments + " >/dev/null 2>&1";
  MeasuredRun run;
  const int status = std::system(command.c_str());
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream peak(peak_path);
  std::int64_t kib = -1;
  if (peak >> kib) run.peak_bytes = kib * 1024;
  std::filesystem::remove(peak_path);
  return run;
}

}  // namespace test
}  // namespace pcl_ddg
