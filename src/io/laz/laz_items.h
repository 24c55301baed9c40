#pragma once
/** \file
 * The LAZ item coders: each codes one item (a fixed part) of a point record from the previous
 * point's item. A LAZ point record is the concatenation of its items, in the order of the
 * LASzip VLR.
 *
 * | item (type id)  | bytes | record part                               | versions coded here |
 * |-----------------|-------|-------------------------------------------|---------------------|
 * | POINT10 (6)     | 20    | formats 0-5: X..point source ID           | 2                   |
 * | GPSTIME11 (7)   | 8     | formats 1, 3-5: GPS time                  | 2                   |
 * | RGB12 (8)       | 6     | formats 2, 3, 5: red, green, blue         | 2                   |
 * | BYTE (0)        | n     | formats 0-5: extra bytes                  | 2                   |
 * | POINT14 (10)    | 30    | formats 6-10: X..GPS time                 | 3, 4                |
 * | RGB14 (11)      | 6     | formats 7, 8, 10: red, green, blue        | 3, 4                |
 * | RGBNIR14 (12)   | 8     | formats 8, 10: red, green, blue, NIR      | 3, 4                |
 * | BYTE14 (14)     | n     | formats 6-10: extra bytes                 | 3, 4                |
 *
 * **Pointwise (version 2) chunks**: the first point of a chunk is stored raw; the following ones
 * are coded, item by item, in one arithmetic-coded stream:
 * - POINT10: a 6-bit mask of the changed fields (return byte, intensity, classification, scan
 *   angle, user data, point source), each changed field coded against the last (bytes with a
 *   256-symbol model per previous value; intensity and point source with integer compressors);
 *   then dX and dY against the median of the last five differences for the return context, and Z
 *   against the last Z of the same return level.
 * - GPSTIME11: the difference to the previous time as integers (the doubles' bit patterns),
 *   coded as a multiple of the last difference plus a corrector, with up to four interleaved
 *   time sequences (for multiple returns) and a raw 64-bit restart when nothing fits.
 * - RGB12: a 7-bit mask of the changed bytes, the low and high bytes of red against the last
 *   red, green and blue predicted by red's change (unless all three are equal).
 * - BYTE: each byte against the last with its own 256-symbol model.
 *
 * **Layered (versions 3, 4) chunks**: the first point raw, the chunk's point count (u32), then
 * the byte counts of every item's layers (u32 each; POINT14 has 9 layers: channel/returns/XY, Z,
 * classification, flags, intensity, scan angle, user data, point source, GPS time; RGB14 one,
 * RGBNIR14 two (RGB, NIR), BYTE14 one per byte), then the layers' bytes in the same order. Each
 * layer is an independent arithmetic-coded stream, and a layer of 0 bytes means the value never
 * changes in the chunk. Points are modelled in up to four contexts, one per scanner channel. In
 * version 3, the non-POINT14 items keep predicting from the previous context's last item on the
 * point where they switch back to an already used context; version 4 fixes that (and is
 * otherwise identical).
 */
#include <cstdint>
#include <memory>
#include <vector>

#include "laz_arithmetic.h"

namespace pcl_ddg {
namespace detail {
namespace laz {

/** LASzip item types (the VLR's ids). */
enum class ItemType : std::uint16_t {
  kByte = 0,
  kPoint10 = 6,
  kGpsTime11 = 7,
  kRgb12 = 8,
  kWavePacket13 = 9,
  kPoint14 = 10,
  kRgb14 = 11,
  kRgbNir14 = 12,
  kWavePacket14 = 13,
  kByte14 = 14,
};

/** One item of the LASzip VLR. */
struct Item {
  ItemType type;
  std::uint16_t size;
  std::uint16_t version;
};

/** A pointwise (version 2) item coder; one instance codes one item of successive points. */
class PointwiseItemCoder {
 public:
  virtual ~PointwiseItemCoder() = default;
  /** Starts a chunk from its raw first point's item. */
  virtual void init(const std::uint8_t* item) = 0;
  virtual void decode(ArithmeticDecoder& dec, std::uint8_t* item) = 0;
  virtual void encode(ArithmeticEncoder& enc, const std::uint8_t* item) = 0;
};

/** The version 2 coder of an item (POINT10, GPSTIME11, RGB12 or BYTE). */
std::unique_ptr<PointwiseItemCoder> makePointwiseCoder(const Item& item, bool decoder);

/** The bytes of one layer in a chunk. */
struct ByteSpan {
  const std::uint8_t* data = nullptr;
  std::uint32_t size = 0;
};

/** A layered (version 3/4) item coder. `context` is the current scanner channel, set by the
 *  POINT14 coder (which comes first) and read by the others. */
class LayeredItemCoder {
 public:
  virtual ~LayeredItemCoder() = default;
  /** Number of layers (u32 byte counts) this item has per chunk. */
  virtual std::uint32_t layerCount() const = 0;

  /** Starts decoding a chunk: `item` is the raw first point's item, `layers` its layers. */
  virtual void initDecoder(const std::uint8_t* item, const ByteSpan* layers,
                           std::uint32_t& context) = 0;
  virtual void decode(std::uint8_t* item, std::uint32_t& context) = 0;

  /** Starts encoding a chunk from its raw first point's item. */
  virtual void initEncoder(const std::uint8_t* item, std::uint32_t& context) = 0;
  virtual void encode(const std::uint8_t* item, std::uint32_t& context) = 0;
  /** Finishes the chunk: appends each layer's bytes (empty when the value never changed). */
  virtual void finishLayers(std::vector<std::vector<std::uint8_t>>& layers) = 0;
};

/** The version 3 or 4 coder of an item (POINT14, RGB14, RGBNIR14 or BYTE14). */
std::unique_ptr<LayeredItemCoder> makeLayeredCoder(const Item& item, bool decoder);

}  // namespace laz
}  // namespace detail
}  // namespace pcl_ddg
