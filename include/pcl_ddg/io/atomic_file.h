#pragma once
/** \file
 * Output that appears complete or not at all: data goes to a temporary file in the target's
 * folder (same file system), which commit() renames over the target. A writer that fails or
 * throws leaves no file behind, because the destructor removes an uncommitted temporary.
 */
#include <string>
#include <string_view>

namespace pcl_ddg {

/** Writes bytes to a new file at path, checking every write and the close (a full disk is
 *  reported, not ignored); throws FileFormatException with the system's reason. */
void writeBytes(const std::string& path, std::string_view bytes);

class AtomicFile {
 public:
  /** Creates an empty, uniquely named temporary next to `path`; throws FileFormatException. */
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /** Where to write the data. */
  const std::string& temporaryPath() const { return temporary_path_; }
  /** Renames the temporary onto the target path; throws FileFormatException on failure. */
  void commit();

  /** Removes the temporaries of all uncommitted AtomicFiles. Async-signal-safe (it only calls
   *  unlink), for use in a signal handler. */
  static void removeUncommittedFiles() noexcept;

  /** Installs SIGINT, SIGTERM and SIGHUP handlers that call removeUncommittedFiles() and then
   *  end the process by the same signal, so that an interrupted program leaves no temporary
   *  behind (and, the rename never having happened, no partial output). */
  static void removeUncommittedFilesOnInterrupt();

 private:
  std::string path_;
  std::string temporary_path_;
  bool committed_ = false;
};

}  // namespace pcl_ddg
