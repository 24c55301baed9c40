// libFuzzer target for LAZ: any input is decompressed or refused with FileFormatException (a
// chunk that runs past its bytes, a lying count or chunk table); what decompresses must parse as
// LAS. A crash, a hang, a sanitizer report or an allocation beyond -malloc_limit_mb is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "las_format.h"
#include "laz/laz_codec.h"
#include "pcl_ddg/exceptions.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pcl_ddg::detail;
  std::string las;
  try {
    las = lazToLas(std::string_view(reinterpret_cast<const char*>(data), size), 2);
  } catch (const pcl_ddg::FileFormatException&) {
    return 0;
  }
  try {
    parseLAS(las);  // a header the decoder let through may still be refused here, with one line
  } catch (const pcl_ddg::FileFormatException&) {
  }
  return 0;
}
