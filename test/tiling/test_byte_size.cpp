// The memory budget's parser (pcl_ddg/tiling/byte_size.h), the tools' -memory and the Dask
// runner's memory_per_worker alike (python/tests/test_distributed.py checks the Python side
// against the same table): sizes written with a unit's powers of 1024, and what is refused.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <cstdint>
#include <string>

#include "pcl_ddg/tiling/byte_size.h"

namespace pcl_ddg {
namespace test {
namespace {

constexpr std::uint64_t kKiB = 1024, kMiB = kKiB * 1024, kGiB = kMiB * 1024, kTiB = kGiB * 1024;

TEST(ByteSize, UnitsArePowersOf1024WithOrWithoutB) {
  const std::pair<const char*, std::uint64_t> sizes[] = {
      {"2G", 2 * kGiB},     {"2GB", 2 * kGiB},     {"2GiB", 2 * kGiB},     {"2g", 2 * kGiB},
      {"512M", 512 * kMiB}, {"512m", 512 * kMiB},  {"512MB", 512 * kMiB},  {"64k", 64 * kKiB},
      {"64K", 64 * kKiB},   {"64kB", 64 * kKiB},   {"1.5G", 3 * kGiB / 2}, {"1T", kTiB},
      {"1000000", 1000000}, {"1000000B", 1000000}, {" 3M ", 3 * kMiB},     {"1e3k", 1000 * kKiB},
      {"0.5k", 512}};
  for (const auto& [text, bytes] : sizes) EXPECT_EQ(parseByteSize(text), bytes) << text;
}

TEST(ByteSize, AnythingElseIsRefusedNamingIt) {
  for (const char* text :
       {"",   "lots", "0",   "0G",  "-1G",  "+1G",  "1kk",  "1x",   "2 G",  "GB",
        "iB", "1iB",  "inf", "nan", "infG", "1e19", "2e6T", "0x10", "1,5G", "1GiBB"}) {
    try {
      parseByteSize(text);
      ADD_FAILURE() << "accepted '" << text << "'";
    } catch (const pcl::BadArgumentException& e) {
      EXPECT_NE(std::string(e.what()).find("'" + std::string(text) + "'"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
