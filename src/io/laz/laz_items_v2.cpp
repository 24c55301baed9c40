// The pointwise (version 2) LAZ item coders: POINT10, GPSTIME11, RGB12 and BYTE (see
// laz_items.h for the format). Each decoder is the exact mirror of its encoder.
#include <array>
#include <string>

#include "laz_item_common.h"
#include "laz_items.h"

namespace pcl_ddg {
namespace detail {
namespace laz {

const std::uint8_t kNumberReturnMap[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
    {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
    {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};

const std::uint8_t kNumberReturnLevel[8][8] = {{0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6},
                                               {2, 1, 0, 1, 2, 3, 4, 5}, {3, 2, 1, 0, 1, 2, 3, 4},
                                               {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2},
                                               {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

namespace {

// ---- POINT10 ----

/** The 20-byte core of formats 0-5: X, Y, Z (i32), intensity (u16), return byte (return number
 *  bits 0-2, number of returns 3-5, scan direction 6, edge 7), classification, scan angle rank,
 *  user data (u8), point source ID (u16). */
class Point10Coder : public PointwiseItemCoder {
 public:
  explicit Point10Coder(bool decoder)
      : decoder_(decoder),
        changed_values_(64, decoder),
        scan_angle_rank_{SymbolModel(256, decoder), SymbolModel(256, decoder)},
        ic_intensity_(16, 4, decoder),
        ic_point_source_(16, 1, decoder),
        ic_dx_(32, 2, decoder),
        ic_dy_(32, 22, decoder),
        ic_z_(32, 20, decoder) {}

  void init(const std::uint8_t* item) override {
    for (int i = 0; i < 16; ++i) {
      last_x_diff_[i].reset();
      last_y_diff_[i].reset();
      last_intensity_[i] = 0;
      last_height_[i / 2] = 0;
    }
    changed_values_.reset();
    scan_angle_rank_[0].reset();
    scan_angle_rank_[1].reset();
    ic_intensity_.reset();
    ic_point_source_.reset();
    for (auto& m : bit_byte_) m.reset();
    for (auto& m : classification_) m.reset();
    for (auto& m : user_data_) m.reset();
    ic_dx_.reset();
    ic_dy_.reset();
    ic_z_.reset();
    std::memcpy(last_, item, 20);
    store<std::uint16_t>(last_ + 12, 0);  // the intensity is predicted from last_intensity_
  }

  void decode(ArithmeticDecoder& dec, std::uint8_t* item) override {
    const std::uint32_t changed = dec.decodeSymbol(changed_values_);
    std::uint32_t r, n, m, l;
    if (changed) {
      if (changed & 32) last_[14] = byteModel(bit_byte_, last_[14], dec);
      r = last_[14] & 7;
      n = (last_[14] >> 3) & 7;
      m = kNumberReturnMap[n][r];
      l = kNumberReturnLevel[n][r];
      if (changed & 16) {
        last_intensity_[m] = static_cast<std::uint16_t>(
            ic_intensity_.decompress(dec, last_intensity_[m], m < 3 ? m : 3));
      }
      store<std::uint16_t>(last_ + 12, last_intensity_[m]);
      if (changed & 8) last_[15] = byteModel(classification_, last_[15], dec);
      if (changed & 4) {
        const std::uint32_t delta = dec.decodeSymbol(scan_angle_rank_[(last_[14] >> 6) & 1]);
        last_[16] = static_cast<std::uint8_t>(delta + last_[16]);
      }
      if (changed & 2) last_[17] = byteModel(user_data_, last_[17], dec);
      if (changed & 1) {
        store<std::uint16_t>(last_ + 18, static_cast<std::uint16_t>(ic_point_source_.decompress(
                                             dec, load<std::uint16_t>(last_ + 18))));
      }
    } else {
      r = last_[14] & 7;
      n = (last_[14] >> 3) & 7;
      m = kNumberReturnMap[n][r];
      l = kNumberReturnLevel[n][r];
    }

    std::int32_t diff = ic_dx_.decompress(dec, last_x_diff_[m].get(), n == 1);
    store<std::int32_t>(last_, wrapAdd(load<std::int32_t>(last_), diff));
    last_x_diff_[m].add(diff);

    std::uint32_t k_bits = ic_dx_.k();
    diff = ic_dy_.decompress(dec, last_y_diff_[m].get(),
                             (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    store<std::int32_t>(last_ + 4, wrapAdd(load<std::int32_t>(last_ + 4), diff));
    last_y_diff_[m].add(diff);

    k_bits = (ic_dx_.k() + ic_dy_.k()) / 2;
    last_height_[l] =
        ic_z_.decompress(dec, last_height_[l], (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
    store<std::int32_t>(last_ + 8, last_height_[l]);

    std::memcpy(item, last_, 20);
  }

  void encode(ArithmeticEncoder& enc, const std::uint8_t* item) override {
    const std::uint32_t r = item[14] & 7;
    const std::uint32_t n = (item[14] >> 3) & 7;
    const std::uint32_t m = kNumberReturnMap[n][r];
    const std::uint32_t l = kNumberReturnLevel[n][r];
    const std::uint16_t intensity = load<std::uint16_t>(item + 12);
    const std::uint16_t point_source = load<std::uint16_t>(item + 18);
    const std::uint16_t last_point_source = load<std::uint16_t>(last_ + 18);

    const std::uint32_t changed =
        ((last_[14] != item[14]) << 5) | ((last_intensity_[m] != intensity) << 4) |
        ((last_[15] != item[15]) << 3) | ((last_[16] != item[16]) << 2) |
        ((last_[17] != item[17]) << 1) | (last_point_source != point_source);
    enc.encodeSymbol(changed_values_, changed);
    if (changed & 32) enc.encodeSymbol(bit_byte_[last_[14]].get(256, decoder_), item[14]);
    if (changed & 16) {
      ic_intensity_.compress(enc, last_intensity_[m], intensity, m < 3 ? m : 3);
      last_intensity_[m] = intensity;
    }
    if (changed & 8) enc.encodeSymbol(classification_[last_[15]].get(256, decoder_), item[15]);
    if (changed & 4) {
      enc.encodeSymbol(scan_angle_rank_[(item[14] >> 6) & 1],
                       foldByte(static_cast<std::int32_t>(item[16]) - last_[16]));
    }
    if (changed & 2) enc.encodeSymbol(user_data_[last_[17]].get(256, decoder_), item[17]);
    if (changed & 1) ic_point_source_.compress(enc, last_point_source, point_source);

    std::int32_t diff = wrapSub(load<std::int32_t>(item), load<std::int32_t>(last_));
    ic_dx_.compress(enc, last_x_diff_[m].get(), diff, n == 1);
    last_x_diff_[m].add(diff);

    std::uint32_t k_bits = ic_dx_.k();
    diff = wrapSub(load<std::int32_t>(item + 4), load<std::int32_t>(last_ + 4));
    ic_dy_.compress(enc, last_y_diff_[m].get(), diff,
                    (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    last_y_diff_[m].add(diff);

    k_bits = (ic_dx_.k() + ic_dy_.k()) / 2;
    const std::int32_t z = load<std::int32_t>(item + 8);
    ic_z_.compress(enc, last_height_[l], z, (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
    last_height_[l] = z;

    std::memcpy(last_, item, 20);
  }

 private:
  /** Decodes a byte with the model selected by its previous value. */
  std::uint8_t byteModel(std::array<LazyModel, 256>& models, std::uint8_t last,
                         ArithmeticDecoder& dec) {
    return static_cast<std::uint8_t>(dec.decodeSymbol(models[last].get(256, decoder_)));
  }

  bool decoder_;
  SymbolModel changed_values_;
  SymbolModel scan_angle_rank_[2];
  IntegerCompressor ic_intensity_, ic_point_source_, ic_dx_, ic_dy_, ic_z_;
  std::array<LazyModel, 256> bit_byte_, classification_, user_data_;
  StreamingMedian5 last_x_diff_[16], last_y_diff_[16];
  std::uint16_t last_intensity_[16] = {};
  std::int32_t last_height_[8] = {};
  std::uint8_t last_[20] = {};
};

// ---- GPSTIME11 ----

/** The GPS time (f64), coded on its bit pattern (see GpsTimeCoder). */
class GpsTime11Coder : public PointwiseItemCoder {
 public:
  explicit GpsTime11Coder(bool decoder) : coder_(true, decoder) {}
  void init(const std::uint8_t* item) override { coder_.reset(load<std::uint64_t>(item)); }
  void decode(ArithmeticDecoder& dec, std::uint8_t* item) override {
    store<std::uint64_t>(item, coder_.decode(dec));
  }
  void encode(ArithmeticEncoder& enc, const std::uint8_t* item) override {
    coder_.encode(enc, load<std::uint64_t>(item));
  }

 private:
  GpsTimeCoder coder_;
};

// ---- RGB12 ----

/** Codes red, green, blue (u16 each) as LASzip's RGB12 v2 / RGB14 v3 do. Shared with the
 *  layered coders through the two free functions below. */
struct RgbModels {
  explicit RgbModels(bool decoder)
      : byte_used(128, decoder), diff{SymbolModel(256, decoder), SymbolModel(256, decoder),
                                      SymbolModel(256, decoder), SymbolModel(256, decoder),
                                      SymbolModel(256, decoder), SymbolModel(256, decoder)} {}
  void reset() {
    byte_used.reset();
    for (auto& m : diff) m.reset();
  }
  SymbolModel byte_used;
  SymbolModel diff[6];
};

}  // namespace

// Not in the anonymous namespace: laz_items_v3.cpp codes RGB14 the same way.
void decodeRgb(ArithmeticDecoder& dec, SymbolModel& byte_used, SymbolModel* diff,
               const std::uint16_t* last, std::uint16_t* rgb);
std::uint32_t encodeRgb(ArithmeticEncoder& enc, SymbolModel& byte_used, SymbolModel* diff,
                        const std::uint16_t* last, const std::uint16_t* rgb);

void decodeRgb(ArithmeticDecoder& dec, SymbolModel& byte_used, SymbolModel* diff,
               const std::uint16_t* last, std::uint16_t* rgb) {
  const std::uint32_t sym = dec.decodeSymbol(byte_used);
  std::int32_t corr;
  if (sym & 1) {
    corr = static_cast<std::int32_t>(dec.decodeSymbol(diff[0]));
    rgb[0] = foldByte(corr + (last[0] & 255));
  } else {
    rgb[0] = last[0] & 0xFF;
  }
  if (sym & 2) {
    corr = static_cast<std::int32_t>(dec.decodeSymbol(diff[1]));
    rgb[0] |= static_cast<std::uint16_t>(foldByte(corr + (last[0] >> 8)) << 8);
  } else {
    rgb[0] |= last[0] & 0xFF00;
  }
  if (sym & (1 << 6)) {  // green and blue differ from red: predicted from red's change
    std::int32_t d = (rgb[0] & 0xFF) - (last[0] & 0xFF);
    if (sym & (1 << 2)) {
      corr = static_cast<std::int32_t>(dec.decodeSymbol(diff[2]));
      rgb[1] = foldByte(corr + clampByte(d + (last[1] & 255)));
    } else {
      rgb[1] = last[1] & 0xFF;
    }
    if (sym & (1 << 4)) {
      corr = static_cast<std::int32_t>(dec.decodeSymbol(diff[4]));
      d = (d + ((rgb[1] & 0xFF) - (last[1] & 0xFF))) / 2;
      rgb[2] = foldByte(corr + clampByte(d + (last[2] & 255)));
    } else {
      rgb[2] = last[2] & 0xFF;
    }
    d = (rgb[0] >> 8) - (last[0] >> 8);
    if (sym & (1 << 3)) {
      corr = static_cast<std::int32_t>(dec.decodeSymbol(diff[3]));
      rgb[1] |= static_cast<std::uint16_t>(foldByte(corr + clampByte(d + (last[1] >> 8))) << 8);
    } else {
      rgb[1] |= last[1] & 0xFF00;
    }
    if (sym & (1 << 5)) {
      corr = static_cast<std::int32_t>(dec.decodeSymbol(diff[5]));
      d = (d + ((rgb[1] >> 8) - (last[1] >> 8))) / 2;
      rgb[2] |= static_cast<std::uint16_t>(foldByte(corr + clampByte(d + (last[2] >> 8))) << 8);
    } else {
      rgb[2] |= last[2] & 0xFF00;
    }
  } else {
    rgb[1] = rgb[0];
    rgb[2] = rgb[0];
  }
}

std::uint32_t encodeRgb(ArithmeticEncoder& enc, SymbolModel& byte_used, SymbolModel* diff,
                        const std::uint16_t* last, const std::uint16_t* rgb) {
  std::int32_t diff_l = 0, diff_h = 0;
  std::uint32_t sym = ((last[0] & 0x00FF) != (rgb[0] & 0x00FF)) << 0;
  sym |= ((last[0] & 0xFF00) != (rgb[0] & 0xFF00)) << 1;
  sym |= ((last[1] & 0x00FF) != (rgb[1] & 0x00FF)) << 2;
  sym |= ((last[1] & 0xFF00) != (rgb[1] & 0xFF00)) << 3;
  sym |= ((last[2] & 0x00FF) != (rgb[2] & 0x00FF)) << 4;
  sym |= ((last[2] & 0xFF00) != (rgb[2] & 0xFF00)) << 5;
  sym |= (((rgb[0] & 0x00FF) != (rgb[1] & 0x00FF)) || ((rgb[0] & 0x00FF) != (rgb[2] & 0x00FF)) ||
          ((rgb[0] & 0xFF00) != (rgb[1] & 0xFF00)) || ((rgb[0] & 0xFF00) != (rgb[2] & 0xFF00)))
         << 6;
  enc.encodeSymbol(byte_used, sym);
  if (sym & 1) {
    diff_l = (rgb[0] & 255) - (last[0] & 255);
    enc.encodeSymbol(diff[0], foldByte(diff_l));
  }
  if (sym & 2) {
    diff_h = (rgb[0] >> 8) - (last[0] >> 8);
    enc.encodeSymbol(diff[1], foldByte(diff_h));
  }
  if (sym & (1 << 6)) {
    if (sym & (1 << 2)) {
      const std::int32_t corr = (rgb[1] & 255) - clampByte(diff_l + (last[1] & 255));
      enc.encodeSymbol(diff[2], foldByte(corr));
    }
    if (sym & (1 << 4)) {
      diff_l = (diff_l + (rgb[1] & 255) - (last[1] & 255)) / 2;
      const std::int32_t corr = (rgb[2] & 255) - clampByte(diff_l + (last[2] & 255));
      enc.encodeSymbol(diff[4], foldByte(corr));
    }
    if (sym & (1 << 3)) {
      const std::int32_t corr = (rgb[1] >> 8) - clampByte(diff_h + (last[1] >> 8));
      enc.encodeSymbol(diff[3], foldByte(corr));
    }
    if (sym & (1 << 5)) {
      diff_h = (diff_h + (rgb[1] >> 8) - (last[1] >> 8)) / 2;
      const std::int32_t corr = (rgb[2] >> 8) - clampByte(diff_h + (last[2] >> 8));
      enc.encodeSymbol(diff[5], foldByte(corr));
    }
  }
  return sym;
}

namespace {

class Rgb12Coder : public PointwiseItemCoder {
 public:
  explicit Rgb12Coder(bool decoder) : models_(decoder) {}
  void init(const std::uint8_t* item) override {
    models_.reset();
    std::memcpy(last_, item, 6);
  }
  void decode(ArithmeticDecoder& dec, std::uint8_t* item) override {
    std::uint16_t rgb[3];
    decodeRgb(dec, models_.byte_used, models_.diff, last_, rgb);
    std::memcpy(last_, rgb, 6);
    std::memcpy(item, rgb, 6);
  }
  void encode(ArithmeticEncoder& enc, const std::uint8_t* item) override {
    std::uint16_t rgb[3];
    std::memcpy(rgb, item, 6);
    encodeRgb(enc, models_.byte_used, models_.diff, last_, rgb);
    std::memcpy(last_, rgb, 6);
  }

 private:
  RgbModels models_;
  std::uint16_t last_[3] = {};
};

// ---- BYTE ----

/** Extra bytes: each byte's difference to the last with a model per byte position. */
class ByteCoder : public PointwiseItemCoder {
 public:
  ByteCoder(std::uint32_t size, bool decoder) : last_(size) {
    models_.reserve(size);
    for (std::uint32_t i = 0; i < size; ++i) models_.emplace_back(256, decoder);
  }
  void init(const std::uint8_t* item) override {
    for (auto& m : models_) m.reset();
    std::memcpy(last_.data(), item, last_.size());
  }
  void decode(ArithmeticDecoder& dec, std::uint8_t* item) override {
    for (std::size_t i = 0; i < last_.size(); ++i) {
      last_[i] = static_cast<std::uint8_t>(last_[i] + dec.decodeSymbol(models_[i]));
    }
    std::memcpy(item, last_.data(), last_.size());
  }
  void encode(ArithmeticEncoder& enc, const std::uint8_t* item) override {
    for (std::size_t i = 0; i < last_.size(); ++i) {
      enc.encodeSymbol(models_[i], foldByte(static_cast<std::int32_t>(item[i]) - last_[i]));
    }
    std::memcpy(last_.data(), item, last_.size());
  }

 private:
  std::vector<SymbolModel> models_;
  std::vector<std::uint8_t> last_;
};

}  // namespace

std::unique_ptr<PointwiseItemCoder> makePointwiseCoder(const Item& item, bool decoder) {
  switch (item.type) {
    case ItemType::kPoint10:
      return std::make_unique<Point10Coder>(decoder);
    case ItemType::kGpsTime11:
      return std::make_unique<GpsTime11Coder>(decoder);
    case ItemType::kRgb12:
      return std::make_unique<Rgb12Coder>(decoder);
    case ItemType::kByte:
      return std::make_unique<ByteCoder>(item.size, decoder);
    default:
      return nullptr;
  }
}

}  // namespace laz
}  // namespace detail
}  // namespace pcl_ddg
