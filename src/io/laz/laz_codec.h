#pragma once
/** \file
 * LAZ (LASzip-compressed LAS) to LAS and back, in memory.
 *
 * A LAZ file is a LAS file whose point format byte has bit 7 (0x80; some writers also bit 6,
 * 0x40) set, with a VLR of user id "laszip encoded", record id 22204, whose payload is
 *
 * | offset | type     | field                                                        |
 * |--------|----------|--------------------------------------------------------------|
 * | 0      | u16      | compressor: 1 pointwise, 2 pointwise-chunked, 3 layered-chunked |
 * | 2      | u16      | coder: 0 arithmetic                                          |
 * | 4      | u8, u8   | LASzip version major, minor                                  |
 * | 6      | u16      | revision                                                     |
 * | 8      | u32      | options                                                      |
 * | 12     | u32      | chunk size in points (0xFFFFFFFF: variable, see the table)   |
 * | 16     | i64, i64 | number of / offset to special EVLRs (-1: unused)             |
 * | 32     | u16      | number of items, then per item: u16 type, u16 size, u16 version |
 *
 * and whose point data is, for the chunked compressors, an i64 offset to the chunk table (-1
 * when the writer could not seek back: the offset is then in the last 8 bytes), the chunks, and
 * the chunk table: u32 version (0), u32 number of chunks, then per chunk (point count, for
 * variable chunks, and) byte count, coded with an IntegerCompressor(32 bits, 2 contexts) from the
 * previous chunk's values. Every chunk restarts the coders, so chunks decode independently (in
 * parallel here). Item coding: see laz_items.h; entropy coding: see laz_arithmetic.h.
 *
 * Supported: point formats 0-3 with the version 2 items (POINT10, GPSTIME11, RGB12, BYTE),
 * pointwise or pointwise-chunked; formats 6-8 with the version 3 or 4 layered items (POINT14,
 * RGB14, RGBNIR14, BYTE14), as written by LASzip 3 and COPC writers. Refused with a message:
 * LASzip 1.x's version 1 items, waveform formats 4, 5, 9, 10, other coders, and anything
 * inconsistent. Corrupt data never reads outside the input and never loops without end: it
 * throws pcl_ddg::FileFormatException naming the chunk. The records are allocated only when the
 * header's count times the record length is at most 2^17 times the compressed point data plus
 * 64 MiB (a million identical points reach about 3,000 times), and fewer threads decode a file
 * whose records are so wide that their decoders (2.5 KB per record byte and channel) would
 * exceed 256 MiB each.
 */
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace pcl_ddg {
namespace detail {

/**
 * The uncompressed LAS file equivalent to a LAZ file: the same header with the compression bits
 * cleared, the LASzip VLR removed (VLR count and point data offset adjusted), the points
 * decompressed and the EVLRs kept (their offset adjusted). Chunks are decoded by up to `threads`
 * threads (at least one).
 * @throws pcl_ddg::FileFormatException if the file is not LAZ, unsupported or corrupt.
 */
std::string lazToLas(std::string_view laz_file_bytes, int threads);

/**
 * The LAZ file equivalent to an uncompressed LAS file of point format 0-3 (version 2 items,
 * pointwise-chunked) or 6-8 (version 3 layered items), in chunks of 50,000 points with a chunk
 * table, the LASzip VLR appended to the VLRs.
 * @throws pcl_ddg::FileFormatException if the file is not a LAS file of those formats.
 */
std::string lasToLaz(std::string_view las_file_bytes);

/** Bytes [offset, offset + count) of a file, which the caller has checked lie within it. */
using ByteReader = std::function<std::string(std::uint64_t offset, std::uint64_t count)>;

/** Where the streaming lasToLaz writes: bytes appended in order, and a few written back over
 *  bytes appended before (the chunk table's offset, the EVLRs' start) once they are known. */
struct LazSink {
  std::function<void(std::string_view bytes)> append;
  std::function<void(std::uint64_t at, std::string_view bytes)> patch;
};

/** lasToLaz of the LAS file of las_size bytes that `read` gives, a chunk of records at a time
 *  (nothing the size of the file is held). */
void lasToLaz(const ByteReader& read, std::uint64_t las_size, const LazSink& out);

/** A chunk of a LAZ file of variable chunks: its point count and its bytes. */
struct LazChunk {
  std::uint32_t points = 0;
  std::string_view bytes;
};

/**
 * The LAZ file holding the given chunks of another (COPC nodes read by byte ranges), in that
 * order: `prefix` is the other file's bytes up to its point data (header and VLRs, its LASzip
 * VLR's chunks of variable size); the header's point count becomes the chunks' and its EVLRs
 * are left out. Its points are then what lazToLas decodes, each chunk checked as in any file.
 * @throws pcl_ddg::FileFormatException if prefix is not such a file's beginning.
 */
std::string lazOfChunks(std::string_view prefix, const std::vector<LazChunk>& chunks);

/** Where a LAZ file's chunks lie, from its chunk table: for reading it a few chunks at a time. */
struct LazChunkIndex {
  std::string prefix;      ///< the file's bytes up to its point data (header and VLRs)
  std::string las_prefix;  ///< the LAS file it stands for up to its points (counting none)
  std::uint16_t record_length = 0;
  struct Span {
    std::uint64_t begin = 0, end = 0;  ///< the chunk's bytes in the file
    std::uint64_t first_point = 0, points = 0;
  };
  std::vector<Span> chunks;
};

/**
 * The chunks of the LAZ file of file_size bytes that read gives: its header and VLRs, the chunk
 * table's offset and the table are read, nothing else.
 * @throws pcl_ddg::FileFormatException for a file that is not LAZ, is corrupt, or whose points
 * cannot be read apart: the pointwise compressor's one stream, a missing or broken chunk table
 * (lazToLas reads such a file whole).
 */
LazChunkIndex indexLazChunks(const ByteReader& read, std::uint64_t file_size);

/** The LAS point records of chunks first..last of index (consecutive), decoded from `bytes`, the
 *  file's from chunk first's begin to chunk last's end, on up to `threads` threads. */
std::string decodeLazChunks(const LazChunkIndex& index, std::size_t first, std::size_t last,
                            std::string_view bytes, int threads);

}  // namespace detail
}  // namespace pcl_ddg
