// libFuzzer target for LAZ: any input is decompressed or refused with FileFormatException (a
// chunk that runs past its bytes, a lying count or chunk table); what decompresses must parse as
// LAS. The input is also read as COPC: its hierarchy, then its nodes by byte ranges. A crash, a
// hang, a sanitizer report or an allocation beyond -malloc_limit_mb is a finding.
#include <pcl/exceptions.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "las_format.h"
#include "laz/laz_codec.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/copc.h"

namespace {

// What the header claims to decompress to: count x record length (LAS 1.4 R15, table 3).
std::uint64_t claimedBytes(const std::uint8_t* data, std::size_t size) {
  if (size < 227) return 0;
  std::uint16_t length;
  std::uint32_t legacy;
  std::memcpy(&length, data + 105, 2);
  std::memcpy(&legacy, data + 107, 4);
  std::uint64_t count = legacy;
  if (size >= 255 && data[25] >= 4) {
    std::uint64_t wide;
    std::memcpy(&wide, data + 247, 8);
    count = std::max<std::uint64_t>(count, wide);
  }
  return count * length;
}

/** The input's bytes as the COPC reader reads a file's. */
class MemoryRanges : public pcl_ddg::detail::ByteRanges {
 public:
  explicit MemoryRanges(std::string_view bytes) : bytes_(bytes) {}
  std::uint64_t size() const override { return bytes_.size(); }
  std::string read(std::uint64_t offset, std::uint64_t count) override {
    bytes_read_ += count;
    return std::string(bytes_.substr(offset, count));
  }

 private:
  std::string_view bytes_;
};

void readAsCopc(std::string_view bytes) {
  MemoryRanges file(bytes);
  try {
    const pcl_ddg::CopcInfo info = pcl_ddg::detail::readCopcInfo(file);
    std::vector<pcl_ddg::CopcKey> keys;
    for (const pcl_ddg::CopcNode& node : info.nodes) keys.push_back(node.key);
    pcl_ddg::detail::parseLAS(pcl_ddg::detail::copcNodesAsLas(file, info, keys));
  } catch (const pcl_ddg::FileFormatException&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pcl_ddg::detail;
  // The codec lets a file decompress to 2^17 times its size (identical points do): a 16 KB input
  // may claim GBs of records that are not a lie. Beyond what the run's malloc limit allows, such
  // claims are left out here, not as findings.
  if (claimedBytes(data, size) > (std::uint64_t{1} << 27)) return 0;
  readAsCopc(std::string_view(reinterpret_cast<const char*>(data), size));
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
