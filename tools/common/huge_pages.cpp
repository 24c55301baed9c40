#include "common/huge_pages.h"

#include <gnu/libc-version.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include "pcl_ddg/large_array.h"

namespace pcl_ddg {
namespace tools {
namespace {

constexpr std::uintmax_t kLargeInputBytes = std::uintmax_t{32} << 20;

/** This process's arguments, argv[0] included, as the kernel holds them (also right when the
 *  tool was started through the dynamic loader, which /proc/self/exe then is). */
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

/** Whether the regular files among the arguments and directly inside the folders among them hold
 *  kLargeInputBytes or more; options and values that name no file count nothing. */
bool largeInputs(const std::vector<std::string>& arguments) {
  namespace fs = std::filesystem;
  std::uintmax_t bytes = 0;
  const auto add = [&bytes](const fs::directory_entry& entry) {
    std::error_code error;
    if (!entry.is_regular_file(error) || error) return false;
    const std::uintmax_t size = entry.file_size(error);
    if (!error) bytes += size;
    return bytes >= kLargeInputBytes;
  };
  for (std::size_t i = 1; i < arguments.size(); ++i) {
    std::error_code error;
    const fs::directory_entry entry(arguments[i], error);
    if (error) continue;
    if (add(entry)) return true;
    if (!entry.is_directory(error) || error) continue;
    for (fs::directory_iterator it(entry.path(), error), end; !error && it != end;
         it.increment(error)) {
      if (add(*it)) return true;
    }
  }
  return false;
}

bool contains(const char* text, const char* part) {
  return text != nullptr && std::strstr(text, part) != nullptr;
}

/** glibc.malloc.hugetlb=1 does something: glibc 2.35 or later, and the kernel's transparent huge
 *  pages in "madvise" mode (in "always" mode they come without it, in "never" not at all). */
bool tunableTakesEffect() {
  int major = 0, minor = 0;
  if (std::sscanf(gnu_get_libc_version(), "%d.%d", &major, &minor) != 2) return false;
  if (major < 2 || (major == 2 && minor < 35)) return false;
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(mode)), std::istreambuf_iterator<char>());
  return modes.find("[madvise]") != std::string::npos;
}

/** The executable's own path, so that the restarted process keeps its name in ps and top
 *  (exec of /proc/self/exe would name it "exe"); /proc/self/exe itself if that path is gone. */
std::string ownExecutable() {
  std::error_code error;
  const std::string path = std::filesystem::read_symlink("/proc/self/exe", error).string();
  const std::string deleted = " (deleted)";
  if (error || path.empty() ||
      (path.size() >= deleted.size() &&
       path.compare(path.size() - deleted.size(), deleted.size(), deleted) == 0)) {
    return "/proc/self/exe";
  }
  return path;
}

}  // namespace

void restartOnHugePagesForLargeInputs() {
  std::vector<std::string> arguments = ownArguments();
  for (const std::string& argument : arguments) {
    // A budget measured in 4 KiB pages: the library's large arrays too stay on them.
    if (argument == "-memory") {
      setenv("PCL_DDG_HUGE_PAGES", "0", 1);
      return;
    }
  }
  const char* tunables_now = std::getenv("GLIBC_TUNABLES");
  if (!detail::hugePagesAllowed() || contains(tunables_now, "glibc.malloc.hugetlb")) return;
  if (arguments.empty() || !largeInputs(arguments) || !tunableTakesEffect()) return;
  const bool had_tunables = tunables_now != nullptr;
  const std::string tunables = had_tunables ? tunables_now : "";  // a copy: setenv may move it
  const std::string set = tunables.empty() ? std::string("glibc.malloc.hugetlb=1")
                                           : tunables + ":glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", set.c_str(), 1) != 0) return;
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  execv(ownExecutable().c_str(), argv.data());
  // Still here: the exec failed. The tool runs without huge pages, and the variable set above
  // would name what this process does not have.
  if (had_tunables) {
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace tools
}  // namespace pcl_ddg
