// libFuzzer target for one file format (PCL_DDG_FUZZ_PARSER names the parser): any input is either
// parsed or refused with FileFormatException; a crash, a hang, a sanitizer report or an
// allocation beyond -malloc_limit_mb is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mesh_formats.h"
#include "pcl_ddg/exceptions.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    pcl_ddg::detail::PCL_DDG_FUZZ_PARSER(
        std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const pcl_ddg::FileFormatException&) {
  }
  return 0;
}
