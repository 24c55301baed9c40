#include "tool_runner.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
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

}  // namespace test
}  // namespace pcl_ddg
