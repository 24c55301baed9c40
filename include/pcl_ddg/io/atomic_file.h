#pragma once
// Output that appears complete or not at all: data goes to a temporary file in the target's
// folder (same file system), which commit() renames over the target. A writer that fails or
// throws leaves no file behind, because the destructor removes an uncommitted temporary.
#include <string>

namespace pcl_ddg {

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

 private:
  std::string path_;
  std::string temporary_path_;
  bool committed_ = false;
};

}  // namespace pcl_ddg
