// LAZ <-> LAS in memory: the LAS header and VLRs around the points, the LASzip VLR, the chunk
// table, and the chunks, decoded by several threads (see laz_codec.h for the layout).
#include "laz_codec.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "laz_item_common.h"
#include "laz_items.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/las_layout.h"

namespace pcl_ddg {
namespace detail {

namespace {

using laz::Item;
using laz::ItemType;
using laz::LazCorruptData;
using laz::load;
using laz::store;

[[noreturn]] void fail(const std::string& message) {
  throw FileFormatException("LAZ: " + message);
}

constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::uint16_t kLaszipRecordId = 22204;
constexpr char kLaszipUserId[] = "laszip encoded";
constexpr std::uint32_t kChunkSize = 50000;  // points per chunk written by lasToLaz
constexpr std::uint32_t kVariableChunks = 0xFFFFFFFFu;
// The records decompressed, at most this many times the compressed bytes plus an allowance: a
// larger claim is a lie, refused before the output is allocated. LASzip reaches 5-20 on surveys,
// about 3,000 on a million identical points of format 0; the bound leaves room above that.
constexpr std::uint64_t kMaxExpansion = std::uint64_t{1} << 17;
constexpr std::uint64_t kByteAllowance = std::uint64_t{1} << 26;
// The memory the decoders of one thread may take (a model per extra byte and scanner channel):
// fewer threads decode a file whose records are that wide.
constexpr std::uint64_t kDecoderBudget = std::uint64_t{1} << 28;

/** The LAS header fields this codec reads or rewrites. */
struct LasHeader {
  int minor = 0;
  std::uint32_t header_size = 0;
  std::uint64_t point_offset = 0;  // offset to point data
  std::uint32_t vlr_count = 0;
  std::uint8_t format_byte = 0;
  std::uint16_t record_length = 0;
  std::uint64_t point_count = 0;
  std::uint64_t points_end = 0;  // the first EVLR or the end of the file
  bool has_evlrs = false;
};

/** The header of a file of file_size bytes from its first bytes `file` (the header and VLRs at
 *  least, or the whole file). */
LasHeader parseHeader(std::string_view file, std::uint64_t file_size) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(file.data());
  if (file.size() < 227 || file.substr(0, 4) != "LASF")
    fail("not a LAS/LAZ file (no \"LASF\" signature and 227-byte header)");
  LasHeader h;
  h.minor = p[25];
  h.header_size = load<std::uint16_t>(p + 94);
  h.point_offset = load<std::uint32_t>(p + 96);
  h.vlr_count = load<std::uint32_t>(p + 100);
  h.format_byte = p[104];
  h.record_length = load<std::uint16_t>(p + 105);
  h.point_count = load<std::uint32_t>(p + 107);
  if (h.header_size < 227 || h.header_size > file.size())
    fail("header size " + std::to_string(h.header_size) + " is not within the file");
  if (h.point_offset < h.header_size || h.point_offset > file_size)
    fail("offset to point data " + std::to_string(h.point_offset) + " is not within the file");
  h.points_end = file_size;
  if (h.minor >= 4 && h.header_size >= 375) {
    const std::uint64_t count = load<std::uint64_t>(p + 247);
    if (count != 0 || h.point_count == 0) h.point_count = count;
    const std::uint64_t evlr_start = load<std::uint64_t>(p + 235);
    const std::uint32_t evlr_count = load<std::uint32_t>(p + 243);
    if (evlr_count > 0) {
      if (evlr_start < h.point_offset || evlr_start > file_size)
        fail("start of the EVLRs " + std::to_string(evlr_start) + " is not after the points");
      h.points_end = evlr_start;
      h.has_evlrs = true;
    }
  }
  return h;
}

LasHeader parseHeader(std::string_view file) {
  return parseHeader(file, file.size());
}

struct Vlr {
  std::size_t offset;  // of its 54-byte header
  std::size_t size;    // header and payload
  bool laszip;
};

std::vector<Vlr> walkVlrs(std::string_view file, const LasHeader& h) {
  std::vector<Vlr> vlrs;
  std::size_t pos = h.header_size;
  // Each VLR takes at least 54 bytes: a count beyond that is refused before the loop.
  if (h.vlr_count > (h.point_offset - h.header_size) / kVlrHeaderSize)
    fail(std::to_string(h.vlr_count) + " VLRs do not fit before the point data");
  for (std::uint32_t i = 0; i < h.vlr_count; ++i) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(file.data()) + pos;
    if (pos + kVlrHeaderSize > h.point_offset)
      fail("VLR " + std::to_string(i + 1) + " runs past the point data");
    const std::size_t size = kVlrHeaderSize + load<std::uint16_t>(p + 20);
    if (pos + size > h.point_offset)
      fail("VLR " + std::to_string(i + 1) + " runs past the point data");
    const std::string_view user_id(file.data() + pos + 2, 16);
    const bool laszip = user_id.substr(0, user_id.find('\0')) == kLaszipUserId &&
                        load<std::uint16_t>(p + 18) == kLaszipRecordId;
    vlrs.push_back({pos, size, laszip});
    pos += size;
  }
  return vlrs;
}

std::size_t vlrsEnd(const LasHeader& h, const std::vector<Vlr>& vlrs) {
  return vlrs.empty() ? h.header_size : vlrs.back().offset + vlrs.back().size;
}

// ---- the LASzip VLR ----

struct LaszipInfo {
  std::uint16_t compressor = 0;
  std::uint32_t chunk_size = 0;
  std::vector<Item> items;
  bool layered = false;
};

const char* itemName(ItemType type) {
  switch (type) {
    case ItemType::kByte:
      return "BYTE";
    case ItemType::kPoint10:
      return "POINT10";
    case ItemType::kGpsTime11:
      return "GPSTIME11";
    case ItemType::kRgb12:
      return "RGB12";
    case ItemType::kWavePacket13:
      return "WAVEPACKET13";
    case ItemType::kPoint14:
      return "POINT14";
    case ItemType::kRgb14:
      return "RGB14";
    case ItemType::kRgbNir14:
      return "RGBNIR14";
    case ItemType::kWavePacket14:
      return "WAVEPACKET14";
    case ItemType::kByte14:
      return "BYTE14";
  }
  return "unknown";
}

std::string describeItems(const std::vector<Item>& items) {
  std::string text;
  for (const Item& item : items) {
    if (!text.empty()) text += ", ";
    text += std::string(itemName(item.type)) + " v" + std::to_string(item.version) + " (" +
            std::to_string(item.size) + " bytes)";
  }
  return text;
}

/** The items LASzip writes for a point format with `extra` extra bytes. */
std::vector<Item> expectedItems(int format, std::uint16_t extra, std::uint16_t version) {
  std::vector<Item> items;
  if (format <= 3) {
    items.push_back({ItemType::kPoint10, 20, version});
    if (format == 1 || format == 3) items.push_back({ItemType::kGpsTime11, 8, version});
    if (format >= 2) items.push_back({ItemType::kRgb12, 6, version});
    if (extra) items.push_back({ItemType::kByte, extra, version});
  } else {
    items.push_back({ItemType::kPoint14, 30, version});
    if (format == 7) items.push_back({ItemType::kRgb14, 6, version});
    if (format == 8) items.push_back({ItemType::kRgbNir14, 8, version});
    if (extra) items.push_back({ItemType::kByte14, extra, version});
  }
  return items;
}

LaszipInfo parseLaszipVlr(std::string_view payload, int format, std::uint16_t record_length) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(payload.data());
  if (payload.size() < 34) fail("the LASzip VLR is shorter than its 34-byte header");
  LaszipInfo info;
  info.compressor = load<std::uint16_t>(p);
  const std::uint16_t coder = load<std::uint16_t>(p + 2);
  info.chunk_size = load<std::uint32_t>(p + 12);
  const std::uint16_t item_count = load<std::uint16_t>(p + 32);
  if (payload.size() < 34 + 6u * item_count)
    fail("the LASzip VLR lists " + std::to_string(item_count) + " items but holds fewer");
  for (std::uint16_t i = 0; i < item_count; ++i) {
    const std::uint8_t* q = p + 34 + 6 * i;
    info.items.push_back({static_cast<ItemType>(load<std::uint16_t>(q)), load<std::uint16_t>(q + 2),
                          load<std::uint16_t>(q + 4)});
  }
  const std::string version = std::to_string(p[4]) + "." + std::to_string(p[5]) + "r" +
                              std::to_string(load<std::uint16_t>(p + 6));
  if (coder != 0) fail("coder " + std::to_string(coder) + " is not LASzip's arithmetic coder");
  for (const Item& item : info.items) {
    if (item.type == ItemType::kWavePacket13 || item.type == ItemType::kWavePacket14)
      fail("waveform packets (" + std::string(itemName(item.type)) + ") are not supported");
    if (item.version == 1)
      fail(
          "the file was written with LASzip's first (version 1) compressors, which are not "
          "read: LASzip " +
          version + ", items " + describeItems(info.items) +
          "; recompress it with a current laszip (laszip -i in.laz -o out.laz)");
  }
  if (info.compressor < 1 || info.compressor > 3)
    fail("compressor " + std::to_string(info.compressor) + " is not supported");
  info.layered = info.compressor == 3;
  if (format > 3 && format < 6)
    fail("point format " + std::to_string(format) + " (with waveform packets) is not supported");
  if (format > 8) fail("point format " + std::to_string(format) + " is not supported");
  const std::uint16_t base = lasPointFormatSize(format);
  if (record_length < base)
    fail("point record length " + std::to_string(record_length) + " is below point format " +
         std::to_string(format) + "'s " + std::to_string(base) + " bytes");
  const bool layered_format = format >= 6;
  if (layered_format != info.layered) {
    fail("compressor " + std::to_string(info.compressor) +
         (info.layered ? " (layered) cannot code point format "
                       : " (pointwise) cannot code point format ") +
         std::to_string(format));
  }
  const std::uint16_t item_version = info.items.empty() ? 0 : info.items.front().version;
  const bool version_ok =
      layered_format ? (item_version == 3 || item_version == 4) : item_version == 2;
  const std::vector<Item> expected =
      expectedItems(format, static_cast<std::uint16_t>(record_length - base), item_version);
  bool match = version_ok && expected.size() == info.items.size();
  for (std::size_t i = 0; match && i < expected.size(); ++i) {
    match = expected[i].type == info.items[i].type && expected[i].size == info.items[i].size &&
            expected[i].version == info.items[i].version;
  }
  if (!match) {
    fail("the LASzip items " + describeItems(info.items) +
         " are not the supported ones for point "
         "format " +
         std::to_string(format) + " with " + std::to_string(record_length) + "-byte records (" +
         describeItems(expectedItems(format, record_length - base, layered_format ? 3 : 2)) + ")");
  }
  return info;
}

// ---- chunks ----

struct Chunk {
  std::uint64_t begin = 0;   // file offset of its raw first point
  std::uint64_t end = 0;     // one past its last byte (the region's end when unknown)
  std::uint64_t points = 0;  // 0: unknown (layered chunks store their count)
};

/** Per-thread decoders of every item. */
class ChunkDecoder {
 public:
  ChunkDecoder(const LaszipInfo& info, std::uint16_t record_length)
      : record_length_(record_length) {
    std::uint32_t offset = 0;
    for (const Item& item : info.items) {
      offsets_.push_back(offset);
      offset += item.size;
      if (info.layered) {
        layered_.push_back(laz::makeLayeredCoder(item, true));
        layer_count_ += layered_.back()->layerCount();
      } else {
        pointwise_.push_back(laz::makePointwiseCoder(item, true));
      }
    }
  }

  /**
   * Decodes `points` points of the chunk in [begin, end) into out (`points` 0: the count the
   * chunk holds, which must not exceed max_points). Returns the end of the chunk's data and sets
   * points to the count decoded.
   */
  const std::uint8_t* decode(const std::uint8_t* begin, const std::uint8_t* end,
                             std::uint64_t& points, std::uint64_t max_points, std::uint8_t* out) {
    if (points == 0 && layered_.empty()) return begin;
    if (static_cast<std::size_t>(end - begin) < record_length_)
      throw LazCorruptData("it is shorter than its first, raw, point");
    std::memcpy(out, begin, record_length_);
    const std::uint8_t* p = begin + record_length_;
    return layered_.empty() ? decodePointwise(p, end, points, out)
                            : decodeLayered(p, end, points, max_points, out);
  }

 private:
  const std::uint8_t* decodePointwise(const std::uint8_t* p, const std::uint8_t* end,
                                      std::uint64_t points, std::uint8_t* out) {
    for (std::size_t i = 0; i < pointwise_.size(); ++i) pointwise_[i]->init(out + offsets_[i]);
    dec_.init(p, end);
    for (std::uint64_t k = 1; k < points; ++k) {
      std::uint8_t* record = out + k * record_length_;
      for (std::size_t i = 0; i < pointwise_.size(); ++i)
        pointwise_[i]->decode(dec_, record + offsets_[i]);
    }
    return dec_.position();
  }

  const std::uint8_t* decodeLayered(const std::uint8_t* p, const std::uint8_t* end,
                                    std::uint64_t& points, std::uint64_t max_points,
                                    std::uint8_t* out) {
    const std::size_t header = 4 + 4 * static_cast<std::size_t>(layer_count_);
    if (static_cast<std::size_t>(end - p) < header)
      throw LazCorruptData("it ends inside its layer sizes");
    const std::uint32_t count = load<std::uint32_t>(p);
    if (points != 0 && count != points) {
      throw LazCorruptData("it holds " + std::to_string(count) +
                           " points where the chunk table "
                           "says " +
                           std::to_string(points));
    }
    if (count == 0 || count > max_points) {
      throw LazCorruptData("its point count " + std::to_string(count) + " is not within 1.." +
                           std::to_string(max_points));
    }
    points = count;
    spans_.resize(layer_count_);
    const std::uint8_t* data = p + header;
    std::uint64_t available = static_cast<std::uint64_t>(end - data);
    for (std::uint32_t i = 0; i < layer_count_; ++i) {
      const std::uint32_t size = load<std::uint32_t>(p + 4 + 4 * i);
      if (size > available) throw LazCorruptData("its layer sizes exceed its bytes");
      available -= size;
      spans_[i] = {data, size};
      data += size;
    }
    std::uint32_t context = 0;
    const laz::ByteSpan* span = spans_.data();
    for (std::size_t i = 0; i < layered_.size(); ++i) {
      layered_[i]->initDecoder(out + offsets_[i], span, context);
      span += layered_[i]->layerCount();
    }
    for (std::uint64_t k = 1; k < count; ++k) {
      std::uint8_t* record = out + k * record_length_;
      for (std::size_t i = 0; i < layered_.size(); ++i)
        layered_[i]->decode(record + offsets_[i], context);
    }
    return data;
  }

  std::uint16_t record_length_;
  std::vector<std::uint32_t> offsets_;
  std::vector<std::unique_ptr<laz::PointwiseItemCoder>> pointwise_;
  std::vector<std::unique_ptr<laz::LayeredItemCoder>> layered_;
  std::uint32_t layer_count_ = 0;
  std::vector<laz::ByteSpan> spans_;
  laz::ArithmeticDecoder dec_;
};

std::string chunkName(std::size_t index, std::size_t count) {
  return "LAZ chunk " + std::to_string(index + 1) + " of " + std::to_string(count);
}

/**
 * The chunk table at `table_offset`, checked against the point data [data_begin, data_end) and
 * the point count; nullopt (with the reason) when missing or unusable.
 */
/** Whether a chunk table may start at table_offset: after the chunks, 8 bytes before data_end. */
bool tableOffsetValid(std::uint64_t data_begin, std::uint64_t data_end, std::int64_t table_offset,
                      std::string& why) {
  if (table_offset < 0 || static_cast<std::uint64_t>(table_offset) < data_begin + 8 ||
      static_cast<std::uint64_t>(table_offset) + 8 > data_end) {
    why = "its offset " + std::to_string(table_offset) + " is not after the chunks";
    return false;
  }
  return true;
}

/** The chunks, from the table's bytes [table_bytes, table_end) (the file's from `table`, a valid
 *  offset, to the end of the point data); the chunks start at data_begin + 8. */
std::optional<std::vector<Chunk>> decodeChunkTable(const std::uint8_t* table_bytes,
                                                   const std::uint8_t* table_end,
                                                   std::uint64_t data_begin, std::uint64_t table,
                                                   const LaszipInfo& info,
                                                   std::uint64_t point_count,
                                                   std::uint16_t record_length, std::string& why) {
  const std::uint64_t chunks_begin = data_begin + 8;
  const std::uint32_t version = load<std::uint32_t>(table_bytes);
  const std::uint32_t count = load<std::uint32_t>(table_bytes + 4);
  if (version != 0) {
    why = "its version is " + std::to_string(version) + ", not 0";
    return std::nullopt;
  }
  // Every chunk holds at least its raw first point.
  if (count > (table - chunks_begin) / record_length + 1) {
    why = "it lists " + std::to_string(count) + " chunks in " +
          std::to_string(table - chunks_begin) + " bytes";
    return std::nullopt;
  }
  const bool variable = info.chunk_size == kVariableChunks || info.chunk_size == 0;
  std::vector<std::uint64_t> counts(count), sizes(count);
  try {
    if (count > 0) {
      laz::ArithmeticDecoder dec;
      dec.init(table_bytes + 8, table_end);
      laz::IntegerCompressor ic(32, 2, true);
      std::int32_t last_count = 0, last_size = 0;
      for (std::uint32_t i = 0; i < count; ++i) {
        if (variable) last_count = ic.decompress(dec, last_count, 0);
        last_size = ic.decompress(dec, last_size, 1);
        counts[i] = static_cast<std::uint32_t>(last_count);
        sizes[i] = static_cast<std::uint32_t>(last_size);
      }
    }
  } catch (const LazCorruptData&) {
    why = "its entries are truncated";
    return std::nullopt;
  }
  std::vector<Chunk> chunks(count);
  std::uint64_t pos = chunks_begin, remaining = point_count;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint64_t points =
        variable ? counts[i] : std::min<std::uint64_t>(info.chunk_size, remaining);
    if (points > remaining || points == 0) {
      why = "its chunks hold more than the header's " + std::to_string(point_count) + " points";
      return std::nullopt;
    }
    if (sizes[i] > table - pos) {
      why = "chunk " + std::to_string(i + 1) + "'s " + std::to_string(sizes[i]) +
            " bytes run past the table";
      return std::nullopt;
    }
    chunks[i] = {pos, pos + sizes[i], points};
    pos += sizes[i];
    remaining -= points;
  }
  if (remaining != 0) {
    why = "its chunks hold " + std::to_string(point_count - remaining) + " of the header's " +
          std::to_string(point_count) + " points";
    return std::nullopt;
  }
  return chunks;
}

std::optional<std::vector<Chunk>> readChunkTable(const std::uint8_t* file, std::uint64_t data_begin,
                                                 std::uint64_t data_end, std::int64_t table_offset,
                                                 const LaszipInfo& info, std::uint64_t point_count,
                                                 std::uint16_t record_length, std::string& why) {
  if (!tableOffsetValid(data_begin, data_end, table_offset, why)) return std::nullopt;
  const auto table = static_cast<std::uint64_t>(table_offset);
  return decodeChunkTable(file + table, file + data_end, data_begin, table, info, point_count,
                          record_length, why);
}

/** Decodes the chunks into out (record k of the file at out + k * record_length). */
void decodeChunks(const std::uint8_t* file, const std::vector<Chunk>& chunks,
                  const LaszipInfo& info, std::uint16_t record_length, std::uint8_t* out,
                  int threads) {
  std::vector<std::uint64_t> first(chunks.size() + 1, 0);
  for (std::size_t i = 0; i < chunks.size(); ++i) first[i + 1] = first[i] + chunks[i].points;

  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::size_t failed_chunk = chunks.size();
  std::string failure;
  std::exception_ptr other_error;
  auto work = [&] {
    try {
      ChunkDecoder decoder(info, record_length);
      for (std::size_t i; (i = next.fetch_add(1)) < chunks.size();) {
        {
          std::lock_guard<std::mutex> lock(mutex);
          if (failed_chunk < i || other_error) return;  // a lower chunk already failed
        }
        std::uint64_t points = chunks[i].points;
        try {
          decoder.decode(file + chunks[i].begin, file + chunks[i].end, points, points,
                         out + first[i] * record_length);
        } catch (const LazCorruptData& e) {
          std::lock_guard<std::mutex> lock(mutex);
          if (i < failed_chunk) {
            failed_chunk = i;
            failure = e.what();
          }
        }
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!other_error) other_error = std::current_exception();
    }
  };
  // A decoder holds about 2.5 KB of models per byte of the record (extra bytes included) and,
  // layered, per scanner channel: within the budget, whatever the record's width.
  const std::uint64_t decoder_bytes = std::uint64_t{2560} * record_length * (info.layered ? 4 : 1);
  const auto affordable =
      static_cast<std::size_t>(std::max<std::uint64_t>(1, kDecoderBudget / decoder_bytes));
  const std::size_t n =
      std::min({static_cast<std::size_t>(std::max(threads, 1)), chunks.size(), affordable});
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (other_error) std::rethrow_exception(other_error);
  if (failed_chunk < chunks.size())
    throw FileFormatException(chunkName(failed_chunk, chunks.size()) + " is corrupt: " + failure);
}

/**
 * Without a chunk table: decodes chunk after chunk from the start of the data, each beginning
 * where the last ended (pointwise) or after its layers (layered).
 */
void decodeSequentially(const std::uint8_t* file, std::uint64_t chunks_begin,
                        std::uint64_t data_end, const LaszipInfo& info, std::uint16_t record_length,
                        std::uint64_t point_count, std::uint8_t* out, const std::string& why) {
  // (The pointwise compressor has one stream: its chunk size field means nothing.)
  const bool variable =
      info.compressor != 1 && (info.chunk_size == kVariableChunks || info.chunk_size == 0);
  if (variable && !info.layered)
    fail("the chunk table is unusable (" + why +
         ") and chunks of variable size cannot be found "
         "without it");
  const std::uint64_t chunk_size = info.compressor == 1 ? point_count : info.chunk_size;
  const std::uint64_t expected_chunks = variable ? 0 : (point_count + chunk_size - 1) / chunk_size;
  ChunkDecoder decoder(info, record_length);
  const std::uint8_t* p = file + chunks_begin;
  std::uint64_t done = 0;
  for (std::size_t index = 0; done < point_count; ++index) {
    const std::uint64_t left = point_count - done;
    std::uint64_t points = variable ? 0 : std::min(chunk_size, left);
    try {
      p = decoder.decode(p, file + data_end, points, left, out + done * record_length);
    } catch (const LazCorruptData& e) {
      const std::string total =
          expected_chunks ? std::to_string(expected_chunks) : std::string("?");
      throw FileFormatException("LAZ chunk " + std::to_string(index + 1) + " of " + total +
                                " (read without a chunk table: " + why +
                                ") is corrupt: " + e.what());
    }
    done += points;
  }
}

}  // namespace

// ---- LAZ -> LAS ----

std::string lazToLas(std::string_view laz_file_bytes, int threads) {
  const std::string_view file = laz_file_bytes;
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(file.data());
  const LasHeader h = parseHeader(file);
  if ((h.format_byte & 0xC0) == 0)
    fail("the file is not compressed (bits 6-7 of its point format byte are clear)");
  const int format = h.format_byte & 0x3F;
  const std::vector<Vlr> vlrs = walkVlrs(file, h);
  const auto laszip = std::find_if(vlrs.begin(), vlrs.end(), [](const Vlr& v) { return v.laszip; });
  if (laszip == vlrs.end())
    fail("the compressed file has no LASzip VLR (\"laszip encoded\", 22204)");
  const LaszipInfo info =
      parseLaszipVlr(file.substr(laszip->offset + kVlrHeaderSize, laszip->size - kVlrHeaderSize),
                     format, h.record_length);

  const std::uint64_t data_begin = h.point_offset, data_end = h.points_end;
  const std::uint64_t data_bytes = data_end - data_begin;
  if (h.point_count * h.record_length > kMaxExpansion * data_bytes + kByteAllowance) {
    fail("the header's " + std::to_string(h.point_count) + " points of " +
         std::to_string(h.record_length) + " bytes cannot be coded in " +
         std::to_string(data_bytes) + " bytes of point data");
  }
  if (h.point_count > (std::numeric_limits<std::size_t>::max() / 2) / h.record_length)
    fail("the header's " + std::to_string(h.point_count) + " points do not fit in memory");

  // The output: header, the other VLRs, any bytes before the points, points, EVLRs.
  const std::uint64_t removed = laszip->size;
  const std::uint64_t new_point_offset = h.point_offset - removed;
  const std::uint64_t point_bytes = h.point_count * h.record_length;
  const std::uint64_t evlr_bytes = file.size() - data_end;
  std::string las;
  las.resize(new_point_offset + point_bytes + evlr_bytes);
  auto* out = reinterpret_cast<std::uint8_t*>(&las[0]);
  std::memcpy(out, bytes, laszip->offset);
  std::memcpy(out + laszip->offset, bytes + laszip->offset + laszip->size,
              h.point_offset - laszip->offset - laszip->size);
  out[104] = static_cast<std::uint8_t>(format);
  store<std::uint32_t>(out + 96, static_cast<std::uint32_t>(new_point_offset));
  store<std::uint32_t>(out + 100, h.vlr_count - 1);
  if (h.has_evlrs) store<std::uint64_t>(out + 235, new_point_offset + point_bytes);
  std::memcpy(out + new_point_offset + point_bytes, bytes + data_end, evlr_bytes);
  std::uint8_t* points_out = out + new_point_offset;
  if (h.point_count == 0) return las;

  if (info.compressor == 1) {  // one stream, no chunk table
    decodeSequentially(bytes, data_begin, data_end, info, h.record_length, h.point_count,
                       points_out, "the pointwise compressor has none");
    return las;
  }
  if (data_bytes < 8) fail("the point data ends before the chunk table's offset");
  std::int64_t table_offset = load<std::int64_t>(bytes + data_begin);
  std::string why;
  std::optional<std::vector<Chunk>> chunks;
  if (table_offset == -1 && data_bytes >= 16) {
    // A writer that could not seek back put the offset at the end of the data.
    table_offset = load<std::int64_t>(bytes + data_end - 8);
    chunks = readChunkTable(bytes, data_begin, data_end - 8, table_offset, info, h.point_count,
                            h.record_length, why);
  } else if (table_offset == static_cast<std::int64_t>(data_begin)) {
    why = "the writer was interrupted before writing it";
  } else {
    chunks = readChunkTable(bytes, data_begin, data_end, table_offset, info, h.point_count,
                            h.record_length, why);
  }
  if (chunks) {
    decodeChunks(bytes, *chunks, info, h.record_length, points_out, threads);
  } else {
    decodeSequentially(bytes, data_begin + 8, data_end, info, h.record_length, h.point_count,
                       points_out, "chunk table unusable: " + why);
  }
  return las;
}

// ---- LAS -> LAZ ----

namespace {

/** Encodes one chunk of `count` records at `records`, appending it to out. */
class ChunkEncoder {
 public:
  ChunkEncoder(const std::vector<Item>& items, std::uint16_t record_length, bool layered)
      : record_length_(record_length) {
    std::uint32_t offset = 0;
    for (const Item& item : items) {
      offsets_.push_back(offset);
      offset += item.size;
      if (layered) {
        layered_.push_back(laz::makeLayeredCoder(item, false));
      } else {
        pointwise_.push_back(laz::makePointwiseCoder(item, false));
      }
    }
  }

  void encode(const std::uint8_t* records, std::uint32_t count, std::string& out) {
    out.append(reinterpret_cast<const char*>(records), record_length_);
    if (layered_.empty()) {
      for (std::size_t i = 0; i < pointwise_.size(); ++i)
        pointwise_[i]->init(records + offsets_[i]);
      enc_.init();
      for (std::uint32_t k = 1; k < count; ++k) {
        const std::uint8_t* record = records + static_cast<std::size_t>(k) * record_length_;
        for (std::size_t i = 0; i < pointwise_.size(); ++i)
          pointwise_[i]->encode(enc_, record + offsets_[i]);
      }
      enc_.done();
      out.append(reinterpret_cast<const char*>(enc_.bytes().data()), enc_.bytes().size());
      return;
    }
    std::uint32_t context = 0;
    for (std::size_t i = 0; i < layered_.size(); ++i)
      layered_[i]->initEncoder(records + offsets_[i], context);
    for (std::uint32_t k = 1; k < count; ++k) {
      const std::uint8_t* record = records + static_cast<std::size_t>(k) * record_length_;
      for (std::size_t i = 0; i < layered_.size(); ++i)
        layered_[i]->encode(record + offsets_[i], context);
    }
    layers_.clear();
    for (auto& coder : layered_) coder->finishLayers(layers_);
    appendU32(out, count);
    for (const auto& layer : layers_) appendU32(out, static_cast<std::uint32_t>(layer.size()));
    for (const auto& layer : layers_)
      out.append(reinterpret_cast<const char*>(layer.data()), layer.size());
  }

  static void appendU32(std::string& out, std::uint32_t v) {
    char b[4];
    std::memcpy(b, &v, 4);
    out.append(b, 4);
  }

 private:
  std::uint16_t record_length_;
  std::vector<std::uint32_t> offsets_;
  std::vector<std::unique_ptr<laz::PointwiseItemCoder>> pointwise_;
  std::vector<std::unique_ptr<laz::LayeredItemCoder>> layered_;
  std::vector<std::vector<std::uint8_t>> layers_;
  laz::ArithmeticEncoder enc_;
};

/** The chunk table: version 0, count, then each chunk's point count when `points` is given (a
 *  variable-chunk file's) and byte count, coded from the previous chunk's. */
std::string chunkTable(const std::vector<std::uint32_t>& points,
                       const std::vector<std::uint32_t>& bytes) {
  std::string table;
  ChunkEncoder::appendU32(table, 0);
  ChunkEncoder::appendU32(table, static_cast<std::uint32_t>(bytes.size()));
  if (bytes.empty()) return table;
  laz::ArithmeticEncoder enc;
  enc.init();
  laz::IntegerCompressor ic(32, 2, false);
  std::int32_t last_points = 0, last_bytes = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (!points.empty()) {
      ic.compress(enc, last_points, static_cast<std::int32_t>(points[i]), 0);
      last_points = static_cast<std::int32_t>(points[i]);
    }
    ic.compress(enc, last_bytes, static_cast<std::int32_t>(bytes[i]), 1);
    last_bytes = static_cast<std::int32_t>(bytes[i]);
  }
  enc.done();
  table.append(reinterpret_cast<const char*>(enc.bytes().data()), enc.bytes().size());
  return table;
}

std::string laszipVlr(const std::vector<Item>& items, bool layered) {
  std::string payload(34 + 6 * items.size(), '\0');
  auto* p = reinterpret_cast<std::uint8_t*>(&payload[0]);
  store<std::uint16_t>(p, layered ? 3 : 2);  // layered-chunked / pointwise-chunked
  store<std::uint16_t>(p + 2, 0);            // arithmetic coder
  p[4] = 3;                                  // written like LASzip 3.4r3
  p[5] = 4;
  store<std::uint16_t>(p + 6, 3);
  store<std::uint32_t>(p + 8, 0);
  store<std::uint32_t>(p + 12, kChunkSize);
  store<std::int64_t>(p + 16, -1);
  store<std::int64_t>(p + 24, -1);
  store<std::uint16_t>(p + 32, static_cast<std::uint16_t>(items.size()));
  for (std::size_t i = 0; i < items.size(); ++i) {
    store<std::uint16_t>(p + 34 + 6 * i, static_cast<std::uint16_t>(items[i].type));
    store<std::uint16_t>(p + 36 + 6 * i, items[i].size);
    store<std::uint16_t>(p + 38 + 6 * i, items[i].version);
  }
  std::string vlr(kVlrHeaderSize, '\0');
  auto* v = reinterpret_cast<std::uint8_t*>(&vlr[0]);
  std::memcpy(v + 2, kLaszipUserId, sizeof(kLaszipUserId) - 1);
  store<std::uint16_t>(v + 18, kLaszipRecordId);
  store<std::uint16_t>(v + 20, static_cast<std::uint16_t>(payload.size()));
  const char description[] = "LASzip-compatible (pcl_ddg)";
  std::memcpy(v + 22, description, sizeof(description) - 1);
  return vlr + payload;
}

}  // namespace

void lasToLaz(const ByteReader& read, std::uint64_t las_size, const LazSink& out) {
  if (las_size < 227) fail("not a LAS/LAZ file (no \"LASF\" signature and 227-byte header)");
  const std::string head = read(0, 227);
  std::uint32_t header_offset;
  std::memcpy(&header_offset, head.data() + 96, 4);
  if (header_offset < 227 || header_offset > las_size)
    fail("offset to point data " + std::to_string(header_offset) + " is not within the file");
  const std::string file = read(0, header_offset);  // header and VLRs
  const LasHeader h = parseHeader(file, las_size);
  if (h.format_byte & 0xC0) fail("the file is already compressed (LAZ)");
  const int format = h.format_byte;
  if (!lazCompressible(format)) {
    fail("point format " + std::to_string(format) +
         " cannot be compressed here (formats 0-3 and "
         "6-8 can)");
  }
  const std::uint16_t base = lasPointFormatSize(format);
  if (h.record_length < base) {
    fail("point record length " + std::to_string(h.record_length) + " is below point format " +
         std::to_string(format) + "'s " + std::to_string(base) + " bytes");
  }
  const std::vector<Vlr> vlrs = walkVlrs(file, h);
  if (std::any_of(vlrs.begin(), vlrs.end(), [](const Vlr& v) { return v.laszip; }))
    fail("the uncompressed file already has a LASzip VLR");
  if (h.point_count > (h.points_end - h.point_offset) / h.record_length) {
    fail("the header's " + std::to_string(h.point_count) + " points of " +
         std::to_string(h.record_length) + " bytes do not fit in the file");
  }
  const bool layered = format >= 6;
  const std::vector<Item> items =
      expectedItems(format, static_cast<std::uint16_t>(h.record_length - base), layered ? 3 : 2);
  const std::string vlr = laszipVlr(items, layered);
  if (h.point_offset + vlr.size() > std::numeric_limits<std::uint32_t>::max())
    fail("the VLRs would exceed the header's 32-bit offset to the point data");
  if (h.vlr_count == std::numeric_limits<std::uint32_t>::max()) fail("too many VLRs");

  // Header, VLRs, the LASzip VLR, any bytes before the points, then the compressed points.
  const std::size_t vlr_end = vlrsEnd(h, vlrs);
  std::string prefix = file.substr(0, vlr_end) + vlr + file.substr(vlr_end);
  const std::uint64_t point_offset = prefix.size();
  auto* header = reinterpret_cast<std::uint8_t*>(&prefix[0]);
  header[104] = static_cast<std::uint8_t>(format | 0x80);
  store<std::uint32_t>(header + 96, static_cast<std::uint32_t>(point_offset));
  store<std::uint32_t>(header + 100, h.vlr_count + 1);
  out.append(prefix);
  out.append(std::string(8, '\0'));  // the chunk table's offset, written back below
  std::uint64_t position = point_offset + 8;

  ChunkEncoder encoder(items, h.record_length, layered);
  std::vector<std::uint32_t> chunk_bytes;
  std::string chunk;
  for (std::uint64_t done = 0; done < h.point_count;) {
    const std::uint32_t count =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(kChunkSize, h.point_count - done));
    const std::string records =
        read(h.point_offset + done * h.record_length, std::uint64_t{count} * h.record_length);
    chunk.clear();
    encoder.encode(reinterpret_cast<const std::uint8_t*>(records.data()), count, chunk);
    if (chunk.size() > std::numeric_limits<std::uint32_t>::max()) fail("a chunk exceeds 4 GiB");
    chunk_bytes.push_back(static_cast<std::uint32_t>(chunk.size()));
    out.append(chunk);
    position += chunk.size();
    done += count;
  }
  std::string offset(8, '\0');
  store<std::int64_t>(reinterpret_cast<std::uint8_t*>(&offset[0]),
                      static_cast<std::int64_t>(position));
  out.patch(point_offset, offset);
  const std::string table = chunkTable({}, chunk_bytes);
  out.append(table);
  position += table.size();
  if (h.has_evlrs) {
    std::string start(8, '\0');
    store<std::uint64_t>(reinterpret_cast<std::uint8_t*>(&start[0]), position);
    out.patch(235, start);
    constexpr std::uint64_t kBlock = std::uint64_t{1} << 24;
    for (std::uint64_t at = h.points_end; at < las_size; at += kBlock)
      out.append(read(at, std::min(kBlock, las_size - at)));
  }
}

std::string lasToLaz(std::string_view las_file_bytes) {
  std::string laz;
  laz.reserve(las_file_bytes.size() / 4 + 4096);
  lasToLaz(
      [&](std::uint64_t offset, std::uint64_t count) {
        return std::string(las_file_bytes.substr(offset, count));
      },
      las_file_bytes.size(),
      {[&](std::string_view bytes) { laz.append(bytes); },
       [&](std::uint64_t at, std::string_view bytes) { laz.replace(at, bytes.size(), bytes); }});
  return laz;
}

std::string lazOfChunks(std::string_view prefix, const std::vector<LazChunk>& chunks) {
  std::string laz(prefix);
  auto* header = reinterpret_cast<std::uint8_t*>(&laz[0]);
  // The other file's EVLRs (a COPC hierarchy) are not carried over.
  if (laz.size() >= 375 && header[25] >= 4 && load<std::uint16_t>(header + 94) >= 375) {
    store<std::uint64_t>(header + 235, 0);
    store<std::uint32_t>(header + 243, 0);
  }
  const LasHeader h = parseHeader(laz);
  if (h.point_offset != laz.size())
    fail("the prefix ends at byte " + std::to_string(laz.size()) + ", not at the point data (" +
         std::to_string(h.point_offset) + ")");
  if ((h.format_byte & 0xC0) == 0) fail("the file is not compressed");
  const std::vector<Vlr> vlrs = walkVlrs(laz, h);
  const auto laszip = std::find_if(vlrs.begin(), vlrs.end(), [](const Vlr& v) { return v.laszip; });
  if (laszip == vlrs.end()) fail("the file has no LASzip VLR");
  const LaszipInfo info = parseLaszipVlr(
      std::string_view(laz).substr(laszip->offset + kVlrHeaderSize, laszip->size - kVlrHeaderSize),
      h.format_byte & 0x3F, h.record_length);
  if (info.compressor == 1) fail("a pointwise-compressed file has no chunks to take apart");
  const bool variable = info.chunk_size == kVariableChunks || info.chunk_size == 0;
  std::vector<std::uint32_t> points, bytes;
  std::uint64_t total = 0;
  laz.append(8, '\0');  // chunk table offset
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const LazChunk& chunk = chunks[i];
    if (chunk.points == 0) continue;  // an empty node has no chunk
    // Fixed-size chunks: the table has no counts, every chunk but the last is full.
    if (!variable && (chunk.points > info.chunk_size ||
                      (chunk.points < info.chunk_size && i + 1 < chunks.size())))
      fail("chunk of " + std::to_string(chunk.points) + " points among chunks of " +
           std::to_string(info.chunk_size));
    points.push_back(chunk.points);
    bytes.push_back(static_cast<std::uint32_t>(chunk.bytes.size()));
    laz.append(chunk.bytes);
    total += chunk.points;
  }
  if (!variable) points.clear();
  header = reinterpret_cast<std::uint8_t*>(&laz[0]);
  const int format = h.format_byte & 0x3F;
  store<std::uint32_t>(header + 107,
                       format < 6 && total <= 0xFFFFFFFFu ? static_cast<std::uint32_t>(total) : 0u);
  if (h.minor >= 4 && h.header_size >= 375) store<std::uint64_t>(header + 247, total);
  store<std::int64_t>(reinterpret_cast<std::uint8_t*>(&laz[h.point_offset]),
                      static_cast<std::int64_t>(laz.size()));
  laz.append(chunkTable(points, bytes));
  return laz;
}

LazChunkIndex indexLazChunks(const ByteReader& read, std::uint64_t file_size) {
  if (file_size < 227) fail("not a LAS/LAZ file (shorter than a header)");
  std::string head = read(0, std::min<std::uint64_t>(375, file_size));
  const std::uint64_t point_offset =
      load<std::uint32_t>(reinterpret_cast<const std::uint8_t*>(head.data()) + 96);
  if (point_offset < 227 || point_offset > file_size)
    fail("offset to point data " + std::to_string(point_offset) + " is not within the file");
  LazChunkIndex index;
  index.prefix = read(0, point_offset);
  // The points end where the EVLRs begin (LAS 1.4), else at the end of the file.
  std::string parsed = index.prefix;
  auto* p = reinterpret_cast<std::uint8_t*>(&parsed[0]);
  std::uint64_t data_end = file_size;
  if (parsed.size() >= 375 && p[25] >= 4 && load<std::uint16_t>(p + 94) >= 375 &&
      load<std::uint32_t>(p + 243) > 0) {
    data_end = load<std::uint64_t>(p + 235);
    if (data_end < point_offset || data_end > file_size)
      fail("start of the EVLRs " + std::to_string(data_end) + " is not after the points");
    store<std::uint64_t>(p + 235, 0);
    store<std::uint32_t>(p + 243, 0);
  }
  const LasHeader h = parseHeader(parsed);
  if ((h.format_byte & 0xC0) == 0) fail("the file is not compressed");
  const std::vector<Vlr> vlrs = walkVlrs(parsed, h);
  const auto laszip = std::find_if(vlrs.begin(), vlrs.end(), [](const Vlr& v) { return v.laszip; });
  if (laszip == vlrs.end())
    fail("the compressed file has no LASzip VLR (\"laszip encoded\", 22204)");
  const LaszipInfo info =
      parseLaszipVlr(std::string_view(parsed).substr(laszip->offset + kVlrHeaderSize,
                                                     laszip->size - kVlrHeaderSize),
                     h.format_byte & 0x3F, h.record_length);
  if (info.compressor == 1)
    fail("its points are one stream (the pointwise compressor): it has no chunks to read apart");
  if (data_end - point_offset < 8) fail("the point data ends before the chunk table's offset");
  const auto offsetAt = [&](std::uint64_t at) {
    const std::string bytes = read(at, 8);
    return load<std::int64_t>(reinterpret_cast<const std::uint8_t*>(bytes.data()));
  };
  std::int64_t table_offset = offsetAt(point_offset);
  std::uint64_t table_end = data_end;
  if (table_offset == -1 && data_end - point_offset >= 16) {
    table_end = data_end - 8;
    table_offset = offsetAt(table_end);
  }
  std::string why;
  std::optional<std::vector<Chunk>> chunks;
  if (tableOffsetValid(point_offset, table_end, table_offset, why)) {
    const auto table = static_cast<std::uint64_t>(table_offset);
    const std::string bytes = read(table, table_end - table);
    const auto* b = reinterpret_cast<const std::uint8_t*>(bytes.data());
    chunks = decodeChunkTable(b, b + bytes.size(), point_offset, table, info, h.point_count,
                              h.record_length, why);
  }
  if (!chunks) fail("its chunk table is unusable (" + why + "): the file is read only whole");
  std::uint64_t first = 0;
  for (const Chunk& c : *chunks) {
    index.chunks.push_back({c.begin, c.end, first, c.points});
    first += c.points;
  }
  index.record_length = h.record_length;
  index.las_prefix = lazToLas(lazOfChunks(index.prefix, {}), 1);
  return index;
}

std::string decodeLazChunks(const LazChunkIndex& index, std::size_t first, std::size_t last,
                            std::string_view bytes, int threads) {
  if (first > last || last >= index.chunks.size() ||
      bytes.size() != index.chunks[last].end - index.chunks[first].begin)
    fail("chunks " + std::to_string(first) + ".." + std::to_string(last) +
         " are not the bytes given");
  std::vector<LazChunk> parts;
  for (std::size_t i = first; i <= last; ++i) {
    const LazChunkIndex::Span& c = index.chunks[i];
    parts.push_back({static_cast<std::uint32_t>(c.points),
                     bytes.substr(c.begin - index.chunks[first].begin, c.end - c.begin)});
  }
  std::string las = lazToLas(lazOfChunks(index.prefix, parts), threads);
  las.erase(0, index.las_prefix.size());
  return las;
}

}  // namespace detail
}  // namespace pcl_ddg
