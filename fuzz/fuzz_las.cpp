// libFuzzer target for LAS: any input is parsed or refused with FileFormatException; a file that
// parses is written back with its own layout and must read again as the same points, fields and
// VLRs (the writer's round trip). A crash, a hang, a sanitizer report, an allocation beyond
// -malloc_limit_mb or a round trip that differs is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "las_format.h"
#include "las_plan.h"
#include "pcl_ddg/exceptions.h"

namespace {

// The written records against the read ones, less the source's encoding records, which the
// writer leaves out (isEncodingRecord).
bool sameRecords(const std::vector<pcl_ddg::LasVariableLengthRecord>& written,
                 const std::vector<pcl_ddg::LasVariableLengthRecord>& read) {
  std::vector<const pcl_ddg::LasVariableLengthRecord*> kept;
  for (const auto& r : read)
    if (!pcl_ddg::detail::isEncodingRecord(r)) kept.push_back(&r);
  if (written.size() != kept.size()) return false;
  for (std::size_t k = 0; k < written.size(); ++k) {
    const auto& a = written[k];
    const auto& b = *kept[k];
    if (a.user_id != b.user_id || a.record_id != b.record_id || a.description != b.description ||
        a.data != b.data)
      return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pcl_ddg::detail;
  LasCloud first;
  try {
    first = parseLAS(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const pcl_ddg::FileFormatException&) {
    return 0;
  }
  // The exact coordinates as double x y z, as the tools save them.
  std::string written;
  try {
    written = encodeLAS(first.mesh.cloud, first.positions, &first.layout);
  } catch (const pcl_ddg::FileFormatException& e) {
    // A file that was read must be writable with its own layout.
    std::fprintf(stderr, "fuzz_las: cannot write what was read: %s\n", e.what());
    std::abort();
  }
  const LasCloud second = parseLAS(written);  // throws (a finding) if the writer made a bad file
  const std::pair<bool, const char*> checks[] = {
      {second.positions == first.positions, "coordinates"},
      {second.mesh.cloud.point_step == first.mesh.cloud.point_step &&
           second.mesh.cloud.data == first.mesh.cloud.data,
       "fields"},
      {sameRecords(second.layout.vlrs, first.layout.vlrs), "VLRs"},
      {sameRecords(second.layout.evlrs, first.layout.evlrs), "EVLRs"},
      {second.layout.point_format == first.layout.point_format &&
           second.layout.record_length == first.layout.record_length,
       "point format"}};
  for (const auto& [same, what] : checks) {
    if (!same) {
      std::fprintf(stderr, "fuzz_las: the written file's %s differ from the input's\n", what);
      std::abort();
    }
  }
  return 0;
}
