#include "pcl_ddg/io/atomic_file.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <vector>

#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {

void writeBytes(const std::string& path, std::string_view bytes) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw FileFormatException("cannot write '" + path + "': " + std::strerror(errno));
  const auto fail = [&](int error) {
    close(fd);
    throw FileFormatException("cannot write '" + path + "': " + std::strerror(error));
  };
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail(n < 0 ? errno : ENOSPC);
    done += static_cast<std::size_t>(n);
  }
  if (close(fd) != 0) {
    throw FileFormatException("cannot write '" + path + "': " + std::strerror(errno));
  }
}

namespace {

// The temporaries a signal handler must remove: fixed slots of stable C strings (no allocation
// or locking can happen inside a handler).
constexpr int kSlots = 64;
std::atomic<const char*> g_uncommitted[kSlots];

void registerTemporary(const char* path) {
  for (auto& slot : g_uncommitted) {
    const char* empty = nullptr;
    if (slot.compare_exchange_strong(empty, path)) return;
  }
  // More than kSlots files open at once: this one is not cleaned up on a signal (only then).
}

void unregisterTemporary(const char* path) {
  for (auto& slot : g_uncommitted) {
    const char* expected = path;
    if (slot.compare_exchange_strong(expected, nullptr)) return;
  }
}

extern "C" void removeAndReraise(int signal_number) {
  AtomicFile::removeUncommittedFiles();
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

}  // namespace

void AtomicFile::removeUncommittedFiles() noexcept {
  for (auto& slot : g_uncommitted) {
    if (const char* path = slot.load()) unlink(path);
  }
}

void AtomicFile::removeUncommittedFilesOnInterrupt() {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action {};
    action.sa_handler = removeAndReraise;
    sigemptyset(&action.sa_mask);
    sigaction(signal_number, &action, nullptr);
  }
}

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  const std::size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  // A file name may take 255 bytes: a long target name is shortened in its temporary's name.
  std::string pattern = folder + "." + name.substr(0, 200) + ".tmp.XXXXXX";
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
  registerTemporary(temporary_path_.c_str());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  unregisterTemporary(temporary_path_.c_str());
  std::remove(temporary_path_.c_str());
}

void AtomicFile::commit() {
  if (std::rename(temporary_path_.c_str(), path_.c_str()) != 0) {
    throw FileFormatException("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  unregisterTemporary(temporary_path_.c_str());
  committed_ = true;
}

}  // namespace pcl_ddg
