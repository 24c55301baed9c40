#include "pcl_ddg/io/atomic_file.h"

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  const std::size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  std::string pattern = folder + "." + name + ".tmp.XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  const int fd = mkstemp(buffer.data());
  if (fd < 0) {
    throw FileFormatException("cannot create a file next to '" + path +
                              "': " + std::strerror(errno));
  }
  // mkstemp creates the file private (0600); give the result the permissions of a plain new file.
  const mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  close(fd);
  temporary_path_ = buffer.data();
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(temporary_path_.c_str());
}

void AtomicFile::commit() {
  if (std::rename(temporary_path_.c_str(), path_.c_str()) != 0) {
    throw FileFormatException("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  committed_ = true;
}

}  // namespace pcl_ddg
