#pragma once
// A whole file read into memory, for the parsers.
#include <cstddef>
#include <string>
#include <string_view>

namespace pcl_ddg {
namespace detail {

/** The bytes of a regular file, read in one go; throws FileFormatException if it cannot be. */
class FileBytes {
 public:
  explicit FileBytes(const std::string& path);
  ~FileBytes();
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;

  std::string_view view() const { return {data_, size_}; }

 private:
  char* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace detail
}  // namespace pcl_ddg
