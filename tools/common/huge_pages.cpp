#include "common/huge_pages.h"

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace pcl_ddg {
namespace tools {
namespace {

constexpr std::uintmax_t kLargeInputBytes = std::uintmax_t{32} << 20;

/** This process's arguments, argv[0] included, as the kernel holds them. */
std::vector<std::string> ownArguments() {
  std::ifstream file("/proc/self/cmdline", std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::vector<std::string> arguments;
  for (std::size_t begin = 0; begin < all.size();) {
    const std::size_t end = all.find('\0', begin);
    arguments.push_back(all.substr(begin, end - begin));
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  return arguments;
}

/** The bytes of the regular files among the arguments and directly inside the folders among
 *  them; options and values that name no file count nothing. */
std::uintmax_t inputBytes(const std::vector<std::string>& arguments) {
  namespace fs = std::filesystem;
  std::uintmax_t bytes = 0;
  std::error_code error;
  for (std::size_t i = 1; i < arguments.size(); ++i) {
    const fs::path path(arguments[i]);
    if (fs::is_regular_file(path, error)) {
      bytes += fs::file_size(path, error);
    } else if (fs::is_directory(path, error)) {
      for (fs::directory_iterator it(path, error), end; !error && it != end; it.increment(error)) {
        if (it->is_regular_file(error)) bytes += it->file_size(error);
      }
    }
    if (bytes >= kLargeInputBytes) return bytes;
  }
  return bytes;
}

bool contains(const char* text, const char* part) {
  return text != nullptr && std::strstr(text, part) != nullptr;
}

}  // namespace

void restartOnHugePagesForLargeInputs() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const char* wanted = std::getenv("PCL_DDG_HUGE_PAGES");
  if (contains(tunables, "glibc.malloc.hugetlb") ||
      (wanted != nullptr && std::strcmp(wanted, "0") == 0) ||
      contains(std::getenv("LD_PRELOAD"), "vgpreload")) {
    return;
  }
  std::vector<std::string> arguments = ownArguments();
  if (arguments.empty() || inputBytes(arguments) < kLargeInputBytes) return;
  const std::string set = tunables == nullptr || *tunables == '\0'
                              ? std::string("glibc.malloc.hugetlb=1")
                              : std::string(tunables) + ":glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", set.c_str(), 1) != 0) return;
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  execv("/proc/self/exe", argv.data());
  // Still here: the exec failed. The tool runs without huge pages, and the variable set above
  // would name what this process does not have.
  if (tunables == nullptr) {
    unsetenv("GLIBC_TUNABLES");
  } else {
    setenv("GLIBC_TUNABLES", tunables, 1);
  }
}

}  // namespace tools
}  // namespace pcl_ddg
