#pragma once
/** \file
 * A memory budget as a user writes it: `pcl_ddg_normals -memory 2G`, the Dask runner's
 * `--memory-per-worker 512MB`. One parser for both, so that a size one accepts the other does too.
 */
#include <cstdint>
#include <string>

namespace pcl_ddg {

/**
 * The bytes of `text`: a positive number, then optionally a unit k, M, G or T (powers of 1024,
 * either case), optionally followed by B or iB: "2G", "2GB", "2GiB", "512m", "64k", "1.5G";
 * "1000000" and "1000000B" are bytes. Spaces around it are ignored.
 * @throws pcl::BadArgumentException for anything else, and beyond 10^18 bytes.
 */
std::uint64_t parseByteSize(const std::string& text);

}  // namespace pcl_ddg
