// The layered (version 3/4) LAZ item coders: POINT14, RGB14, RGBNIR14 and BYTE14 (see
// laz_items.h for the format). Each decoder is the exact mirror of its encoder, down to
// LASzip's version 3 habit of predicting from a stale last item on a switch of scanner channel.
#include <array>
#include <functional>
#include <utility>

#include "laz_item_common.h"
#include "laz_items.h"

namespace pcl_ddg {
namespace detail {
namespace laz {

const std::uint8_t kNumberReturnMap6[16][16] = {{0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5},
                                                {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
                                                {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3},
                                                {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4},
                                                {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
                                                {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

const std::uint8_t kNumberReturnLevel8[16][16] = {{0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7, 7, 7, 7},
                                                  {1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7, 7, 7},
                                                  {2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7, 7},
                                                  {3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7},
                                                  {4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7},
                                                  {5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7},
                                                  {6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7},
                                                  {7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7},
                                                  {7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7},
                                                  {7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6},
                                                  {7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5},
                                                  {7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4},
                                                  {7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3},
                                                  {7, 7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2},
                                                  {7, 7, 7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1},
                                                  {7, 7, 7, 7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0}};

// Shared with RGB12 (laz_items_v2.cpp).
void decodeRgb(ArithmeticDecoder& dec, SymbolModel& byte_used, SymbolModel* diff,
               const std::uint16_t* last, std::uint16_t* rgb);
std::uint32_t encodeRgb(ArithmeticEncoder& enc, SymbolModel& byte_used, SymbolModel* diff,
                        const std::uint16_t* last, const std::uint16_t* rgb);

namespace {

// ---- POINT14 ----

/** The fields of the 30-byte core of formats 6-10. */
struct Point14 {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t intensity = 0;
  std::uint8_t return_number = 0, number_of_returns = 0;  // 4 bits each
  std::uint8_t classification_flags = 0, scanner_channel = 0, scan_direction = 0, edge = 0;
  std::uint8_t classification = 0, user_data = 0;
  std::int16_t scan_angle = 0;
  std::uint16_t point_source = 0;
  std::uint64_t gps_time = 0;    // the f64's bits
  bool gps_time_change = false;  // whether this point's time differed from the last

  /** Flags byte of the flags layer: edge, scan direction, classification flags. */
  std::uint32_t flags() const { return (edge << 5) | (scan_direction << 4) | classification_flags; }

  static Point14 unpack(const std::uint8_t* p) {
    Point14 q;
    q.x = load<std::int32_t>(p);
    q.y = load<std::int32_t>(p + 4);
    q.z = load<std::int32_t>(p + 8);
    q.intensity = load<std::uint16_t>(p + 12);
    q.return_number = p[14] & 15;
    q.number_of_returns = p[14] >> 4;
    q.classification_flags = p[15] & 15;
    q.scanner_channel = (p[15] >> 4) & 3;
    q.scan_direction = (p[15] >> 6) & 1;
    q.edge = p[15] >> 7;
    q.classification = p[16];
    q.user_data = p[17];
    q.scan_angle = load<std::int16_t>(p + 18);
    q.point_source = load<std::uint16_t>(p + 20);
    q.gps_time = load<std::uint64_t>(p + 22);
    return q;
  }
  void pack(std::uint8_t* p) const {
    store(p, x);
    store(p + 4, y);
    store(p + 8, z);
    store(p + 12, intensity);
    p[14] = static_cast<std::uint8_t>(return_number | (number_of_returns << 4));
    p[15] = static_cast<std::uint8_t>(classification_flags | (scanner_channel << 4) |
                                      (scan_direction << 6) | (edge << 7));
    p[16] = classification;
    p[17] = user_data;
    store(p + 18, scan_angle);
    store(p + 20, point_source);
    store(p + 22, gps_time);
  }
};

/** The models and state of one scanner channel. */
struct Point14Context {
  explicit Point14Context(bool decoder)
      : changed_values{SymbolModel(128, decoder), SymbolModel(128, decoder),
                       SymbolModel(128, decoder), SymbolModel(128, decoder),
                       SymbolModel(128, decoder), SymbolModel(128, decoder),
                       SymbolModel(128, decoder), SymbolModel(128, decoder)},
        scanner_channel(3, decoder),
        return_number_gps_same(13, decoder),
        ic_dx(32, 2, decoder),
        ic_dy(32, 22, decoder),
        ic_z(32, 20, decoder),
        ic_intensity(16, 4, decoder),
        ic_scan_angle(16, 2, decoder),
        ic_point_source(16, 1, decoder),
        gps(false, decoder) {}

  /** Starts the context from `item` (a chunk's first point, or another channel's last). */
  void reset(const Point14& item) {
    for (auto& m : changed_values) m.reset();
    scanner_channel.reset();
    for (auto& m : number_of_returns) m.reset();
    for (auto& m : return_number) m.reset();
    return_number_gps_same.reset();
    ic_dx.reset();
    ic_dy.reset();
    for (int i = 0; i < 12; ++i) {
      last_x_diff[i].reset();
      last_y_diff[i].reset();
    }
    ic_z.reset();
    for (auto& z : last_z) z = item.z;
    for (auto& m : classification) m.reset();
    for (auto& m : flags) m.reset();
    for (auto& m : user_data) m.reset();
    ic_intensity.reset();
    for (auto& v : last_intensity) v = item.intensity;
    ic_scan_angle.reset();
    ic_point_source.reset();
    gps.reset(item.gps_time);
    last_item = item;
    last_item.gps_time_change = false;
    unused = false;
  }

  SymbolModel changed_values[8];
  SymbolModel scanner_channel;
  std::array<LazyModel, 16> number_of_returns, return_number;
  SymbolModel return_number_gps_same;
  IntegerCompressor ic_dx, ic_dy, ic_z;
  std::array<LazyModel, 64> classification, flags, user_data;
  IntegerCompressor ic_intensity, ic_scan_angle, ic_point_source;
  GpsTimeCoder gps;
  StreamingMedian5 last_x_diff[12], last_y_diff[12];
  std::int32_t last_z[8] = {};
  std::uint16_t last_intensity[8] = {};
  Point14 last_item;
  bool unused = true;
};

enum Layer14 {
  kChannelReturnsXY,
  kZ,
  kClassification,
  kFlags,
  kIntensity,
  kScanAngle,
  kUserData,
  kPointSource,
  kGpsTime,
  kLayers14
};

// A chunk's layer from its encoder: the bytes, or none where the values never changed in the
// chunk (an empty layer: the decoder repeats the last value).
void appendLayer(ArithmeticEncoder& encoder, bool changed,
                 std::vector<std::vector<std::uint8_t>>& layers) {
  if (!changed) {
    layers.emplace_back();
    return;
  }
  encoder.done();
  layers.push_back(encoder.bytes());
}

class Point14Coder : public LayeredItemCoder {
 public:
  explicit Point14Coder(bool decoder) : decoder_(decoder) {}
  std::uint32_t layerCount() const override { return kLayers14; }

  void initDecoder(const std::uint8_t* item, const ByteSpan* layers,
                   std::uint32_t& context) override {
    for (int i = 0; i < kLayers14; ++i) {
      // The first layer is always decoded (LASzip reads it even when empty).
      changed_[i] = i == kChannelReturnsXY || layers[i].size > 0;
      if (changed_[i]) dec_[i].init(layers[i].data, layers[i].data + layers[i].size);
    }
    startChunk(item, context);
  }

  void decode(std::uint8_t* item, std::uint32_t& context) override {
    ArithmeticDecoder& dec = dec_[kChannelReturnsXY];
    Point14Context* c = contexts_[current_].get();
    Point14* last = &c->last_item;

    // Context of the last point's return (single / first / last / intermediate) and time change.
    const std::uint32_t lpr = (last->return_number == 1 ? 1 : 0) +
                              (last->return_number >= last->number_of_returns ? 2 : 0) +
                              (last->gps_time_change ? 4 : 0);
    const std::uint32_t changed = dec.decodeSymbol(c->changed_values[lpr]);

    if (changed & (1 << 6)) {  // another scanner channel
      const std::uint32_t channel = (current_ + dec.decodeSymbol(c->scanner_channel) + 1) % 4;
      if (isUnused(channel)) startContext(channel, c->last_item);
      current_ = channel;
      context = current_;
      c = contexts_[current_].get();
      last = &c->last_item;
      last->scanner_channel = static_cast<std::uint8_t>(channel);
    }
    const bool point_source_change = changed & (1 << 5);
    const bool gps_time_change = changed & (1 << 4);
    const bool scan_angle_change = changed & (1 << 3);

    const std::uint32_t last_n = last->number_of_returns;
    const std::uint32_t last_r = last->return_number;
    std::uint32_t n = last_n;
    if (changed & (1 << 2)) {
      n = dec.decodeSymbol(c->number_of_returns[last_n].get(16, decoder_));
      last->number_of_returns = static_cast<std::uint8_t>(n);
    }
    std::uint32_t r = last_r;
    switch (changed & 3) {
      case 1:
        r = (last_r + 1) % 16;
        break;
      case 2:
        r = (last_r + 15) % 16;
        break;
      case 3:
        if (gps_time_change) {
          r = dec.decodeSymbol(c->return_number[last_r].get(16, decoder_));
        } else {
          r = (last_r + dec.decodeSymbol(c->return_number_gps_same) + 2) % 16;
        }
        break;
      default:
        break;
    }
    last->return_number = static_cast<std::uint8_t>(r);

    const std::uint32_t m = kNumberReturnMap6[n][r];
    const std::uint32_t l = kNumberReturnLevel8[n][r];
    const std::uint32_t cpr = (r == 1 ? 1 : 0) + (r >= n ? 2 : 0);  // this point's return
    const std::uint32_t xy = (m << 1) | gps_time_change;

    std::int32_t diff = c->ic_dx.decompress(dec, c->last_x_diff[xy].get(), n == 1);
    last->x = wrapAdd(last->x, diff);
    c->last_x_diff[xy].add(diff);
    std::uint32_t k_bits = c->ic_dx.k();
    diff = c->ic_dy.decompress(dec, c->last_y_diff[xy].get(),
                               (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    last->y = wrapAdd(last->y, diff);
    c->last_y_diff[xy].add(diff);

    if (changed_[kZ]) {
      k_bits = (c->ic_dx.k() + c->ic_dy.k()) / 2;
      last->z = c->ic_z.decompress(dec_[kZ], c->last_z[l],
                                   (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
      c->last_z[l] = last->z;
    }
    if (changed_[kClassification]) {
      const std::uint32_t ccc = ((last->classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
      last->classification = static_cast<std::uint8_t>(
          dec_[kClassification].decodeSymbol(c->classification[ccc].get(256, decoder_)));
    }
    if (changed_[kFlags]) {
      const std::uint32_t flags =
          dec_[kFlags].decodeSymbol(c->flags[last->flags()].get(64, decoder_));
      last->edge = (flags >> 5) & 1;
      last->scan_direction = (flags >> 4) & 1;
      last->classification_flags = flags & 0x0F;
    }
    if (changed_[kIntensity]) {
      const std::uint32_t slot = (cpr << 1) | gps_time_change;
      c->last_intensity[slot] = static_cast<std::uint16_t>(
          c->ic_intensity.decompress(dec_[kIntensity], c->last_intensity[slot], cpr));
      last->intensity = c->last_intensity[slot];
    }
    if (changed_[kScanAngle] && scan_angle_change) {
      last->scan_angle = static_cast<std::int16_t>(
          c->ic_scan_angle.decompress(dec_[kScanAngle], last->scan_angle, gps_time_change));
    }
    if (changed_[kUserData]) {
      last->user_data = static_cast<std::uint8_t>(
          dec_[kUserData].decodeSymbol(c->user_data[last->user_data / 4].get(256, decoder_)));
    }
    if (changed_[kPointSource] && point_source_change) {
      last->point_source = static_cast<std::uint16_t>(
          c->ic_point_source.decompress(dec_[kPointSource], last->point_source));
    }
    if (changed_[kGpsTime] && gps_time_change) last->gps_time = c->gps.decode(dec_[kGpsTime]);

    last->pack(item);
    last->gps_time_change = gps_time_change;
  }

  void initEncoder(const std::uint8_t* item, std::uint32_t& context) override {
    for (auto& e : enc_) e.init();
    for (auto& c : changed_) c = false;
    startChunk(item, context);
  }

  void encode(const std::uint8_t* raw, std::uint32_t& context) override {
    const Point14 item = Point14::unpack(raw);
    Point14* last = &contexts_[current_]->last_item;
    const std::uint32_t lpr = (last->return_number == 1 ? 1 : 0) +
                              (last->return_number >= last->number_of_returns ? 2 : 0) +
                              (last->gps_time_change ? 4 : 0);
    const std::uint32_t channel = item.scanner_channel;
    if (channel != current_ && !isUnused(channel)) last = &contexts_[channel]->last_item;

    const bool point_source_change = item.point_source != last->point_source;
    const bool gps_time_change = item.gps_time != last->gps_time;  // bitwise: -0.0 and NaN too
    const bool scan_angle_change = item.scan_angle != last->scan_angle;
    const std::uint32_t last_n = last->number_of_returns;
    const std::uint32_t last_r = last->return_number;
    const std::uint32_t n = item.number_of_returns;
    const std::uint32_t r = item.return_number;

    std::uint32_t changed = ((channel != current_) << 6) | (point_source_change << 5) |
                            (gps_time_change << 4) | (scan_angle_change << 3) |
                            ((n != last_n) << 2);
    if (r != last_r) {
      if (r == (last_r + 1) % 16) {
        changed |= 1;
      } else if (r == (last_r + 15) % 16) {
        changed |= 2;
      } else {
        changed |= 3;
      }
    }
    ArithmeticEncoder& enc = enc_[kChannelReturnsXY];
    enc.encodeSymbol(contexts_[current_]->changed_values[lpr], changed);

    if (changed & (1 << 6)) {
      enc.encodeSymbol(contexts_[current_]->scanner_channel, (channel - current_ + 3) % 4);
      if (isUnused(channel)) {
        startContext(channel, contexts_[current_]->last_item);
        last = &contexts_[channel]->last_item;
      }
      current_ = channel;
      context = current_;
    }
    Point14Context* c = contexts_[current_].get();

    if (changed & (1 << 2)) enc.encodeSymbol(c->number_of_returns[last_n].get(16, decoder_), n);
    if ((changed & 3) == 3) {
      if (gps_time_change) {
        enc.encodeSymbol(c->return_number[last_r].get(16, decoder_), r);
      } else {
        enc.encodeSymbol(c->return_number_gps_same, (r - last_r + 16 - 2) % 16);
      }
    }

    const std::uint32_t m = kNumberReturnMap6[n][r];
    const std::uint32_t l = kNumberReturnLevel8[n][r];
    const std::uint32_t cpr = (r == 1 ? 1 : 0) + (r >= n ? 2 : 0);
    const std::uint32_t xy = (m << 1) | gps_time_change;

    std::int32_t diff = wrapSub(item.x, last->x);
    c->ic_dx.compress(enc, c->last_x_diff[xy].get(), diff, n == 1);
    c->last_x_diff[xy].add(diff);
    std::uint32_t k_bits = c->ic_dx.k();
    diff = wrapSub(item.y, last->y);
    c->ic_dy.compress(enc, c->last_y_diff[xy].get(), diff,
                      (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    c->last_y_diff[xy].add(diff);

    k_bits = (c->ic_dx.k() + c->ic_dy.k()) / 2;
    c->ic_z.compress(enc_[kZ], c->last_z[l], item.z,
                     (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
    c->last_z[l] = item.z;

    if (item.classification != last->classification) changed_[kClassification] = true;
    const std::uint32_t ccc = ((last->classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
    enc_[kClassification].encodeSymbol(c->classification[ccc].get(256, decoder_),
                                       item.classification);

    if (item.flags() != last->flags()) changed_[kFlags] = true;
    enc_[kFlags].encodeSymbol(c->flags[last->flags()].get(64, decoder_), item.flags());

    if (item.intensity != last->intensity) changed_[kIntensity] = true;
    const std::uint32_t slot = (cpr << 1) | gps_time_change;
    c->ic_intensity.compress(enc_[kIntensity], c->last_intensity[slot], item.intensity, cpr);
    c->last_intensity[slot] = item.intensity;

    if (scan_angle_change) {
      changed_[kScanAngle] = true;
      c->ic_scan_angle.compress(enc_[kScanAngle], last->scan_angle, item.scan_angle,
                                gps_time_change);
    }
    if (item.user_data != last->user_data) changed_[kUserData] = true;
    enc_[kUserData].encodeSymbol(c->user_data[last->user_data / 4].get(256, decoder_),
                                 item.user_data);
    if (point_source_change) {
      changed_[kPointSource] = true;
      c->ic_point_source.compress(enc_[kPointSource], last->point_source, item.point_source);
    }
    if (gps_time_change) {
      changed_[kGpsTime] = true;
      c->gps.encode(enc_[kGpsTime], item.gps_time);
    }
    *last = item;
    last->gps_time_change = gps_time_change;
  }

  void finishLayers(std::vector<std::vector<std::uint8_t>>& layers) override {
    // X/Y and Z are always written; the others only when their value changed in the chunk.
    for (int i = 0; i < kLayers14; ++i)
      appendLayer(enc_[i], i == kChannelReturnsXY || i == kZ || changed_[i], layers);
  }

 private:
  bool isUnused(std::uint32_t channel) const {
    return !contexts_[channel] || contexts_[channel]->unused;
  }
  void startContext(std::uint32_t channel, Point14 item) {  // a copy: item may be another's last
    if (!contexts_[channel]) contexts_[channel] = std::make_unique<Point14Context>(decoder_);
    contexts_[channel]->reset(item);
  }
  void startChunk(const std::uint8_t* raw, std::uint32_t& context) {
    for (auto& c : contexts_) {
      if (c) c->unused = true;
    }
    const Point14 item = Point14::unpack(raw);
    current_ = item.scanner_channel;
    context = current_;
    startContext(current_, item);
  }

  bool decoder_;
  std::unique_ptr<Point14Context> contexts_[4];
  std::uint32_t current_ = 0;
  ArithmeticDecoder dec_[kLayers14];
  ArithmeticEncoder enc_[kLayers14];
  bool changed_[kLayers14] = {};
};

// ---- RGB14, RGBNIR14, BYTE14 ----

/**
 * Base of the items that follow POINT14's scanner channel: per channel, models and the last
 * item (`Words` u16 or u8 values). On a switch to an unused channel the new context starts from
 * the current last item; on a switch to a used one, version 3 still predicts this point from the
 * previous channel's last item (and stores it there), version 4 from the channel's own.
 */
template <typename Models, typename Value>
class ChannelContexts {
 public:
  using Factory = std::function<std::unique_ptr<Models>()>;
  ChannelContexts(std::size_t values, bool stale_switch, Factory make)
      : values_(values), stale_(stale_switch), make_(std::move(make)) {}

  /** Starts a chunk on `context` from `item`. */
  void start(const Value* item, std::uint32_t context) {
    for (auto& c : contexts_) c.unused = true;
    current_ = context;
    begin(current_, item);
  }
  /** The models and last item for this point (switching context as needed). */
  std::pair<Models*, Value*> select(std::uint32_t context) {
    Value* last = contexts_[current_].last.data();
    if (current_ != context) {
      current_ = context;
      if (contexts_[current_].unused) {
        begin(current_, last);
        last = contexts_[current_].last.data();
      } else if (!stale_) {
        last = contexts_[current_].last.data();
      }
    }
    return {contexts_[current_].models.get(), last};
  }

 private:
  struct Context {
    std::unique_ptr<Models> models;
    std::vector<Value> last;
    bool unused = true;
  };
  void begin(std::uint32_t context, const Value* item) {
    Context& c = contexts_[context];
    if (!c.models) c.models = make_();
    c.models->reset();
    std::vector<Value> copy(item, item + values_);  // item may be another context's last
    c.last = std::move(copy);
    c.unused = false;
  }

  std::size_t values_;
  bool stale_;
  Factory make_;
  Context contexts_[4];
  std::uint32_t current_ = 0;
};

struct RgbNirModels {
  explicit RgbNirModels(bool decoder)
      : rgb_used(128, decoder),
        rgb{SymbolModel(256, decoder), SymbolModel(256, decoder), SymbolModel(256, decoder),
            SymbolModel(256, decoder), SymbolModel(256, decoder), SymbolModel(256, decoder)},
        nir_used(4, decoder),
        nir{SymbolModel(256, decoder), SymbolModel(256, decoder)} {}
  void reset() {
    rgb_used.reset();
    for (auto& m : rgb) m.reset();
    nir_used.reset();
    for (auto& m : nir) m.reset();
  }
  SymbolModel rgb_used;
  SymbolModel rgb[6];
  SymbolModel nir_used;
  SymbolModel nir[2];
};

/** RGB14 (`nir` false: 3 values, one layer) and RGBNIR14 (4 values, layers RGB and NIR). */
class RgbNir14Coder : public LayeredItemCoder {
 public:
  RgbNir14Coder(bool nir, bool decoder, bool stale_switch)
      : nir_(nir), contexts_(nir ? 4 : 3, stale_switch, [decoder] {
          return std::make_unique<RgbNirModels>(decoder);
        }) {}
  std::uint32_t layerCount() const override { return nir_ ? 2 : 1; }

  void initDecoder(const std::uint8_t* item, const ByteSpan* layers,
                   std::uint32_t& context) override {
    for (std::uint32_t i = 0; i < layerCount(); ++i) {
      changed_[i] = layers[i].size > 0;
      if (changed_[i]) dec_[i].init(layers[i].data, layers[i].data + layers[i].size);
    }
    start(item, context);
  }

  void decode(std::uint8_t* item, std::uint32_t& context) override {
    auto [models, last] = contexts_.select(context);
    std::uint16_t value[4];
    if (changed_[0]) {
      decodeRgb(dec_[0], models->rgb_used, models->rgb, last, value);
      std::memcpy(last, value, 6);
    } else {
      std::memcpy(value, last, 6);
    }
    if (nir_) {
      if (changed_[1]) {
        const std::uint32_t sym = dec_[1].decodeSymbol(models->nir_used);
        std::uint32_t low = last[3] & 0xFF;
        std::uint32_t high = last[3] >> 8;
        if (sym & 1)
          low = foldByte(static_cast<std::int32_t>(dec_[1].decodeSymbol(models->nir[0]) + low));
        if (sym & 2)
          high = foldByte(static_cast<std::int32_t>(dec_[1].decodeSymbol(models->nir[1]) + high));
        last[3] = static_cast<std::uint16_t>(low | (high << 8));
      }
      value[3] = last[3];
    }
    std::memcpy(item, value, nir_ ? 8 : 6);
  }

  void initEncoder(const std::uint8_t* item, std::uint32_t& context) override {
    for (auto& e : enc_) e.init();
    changed_[0] = changed_[1] = false;
    start(item, context);
  }

  void encode(const std::uint8_t* item, std::uint32_t& context) override {
    auto [models, last] = contexts_.select(context);
    std::uint16_t value[4];
    std::memcpy(value, item, nir_ ? 8 : 6);
    if (encodeRgb(enc_[0], models->rgb_used, models->rgb, last, value)) changed_[0] = true;
    if (nir_) {
      const std::uint32_t sym = ((last[3] & 0x00FF) != (value[3] & 0x00FF)) |
                                (((last[3] & 0xFF00) != (value[3] & 0xFF00)) << 1);
      enc_[1].encodeSymbol(models->nir_used, sym);
      if (sym & 1)
        enc_[1].encodeSymbol(models->nir[0], foldByte((value[3] & 255) - (last[3] & 255)));
      if (sym & 2) enc_[1].encodeSymbol(models->nir[1], foldByte((value[3] >> 8) - (last[3] >> 8)));
      if (sym) changed_[1] = true;
    }
    std::memcpy(last, value, nir_ ? 8 : 6);
  }

  void finishLayers(std::vector<std::vector<std::uint8_t>>& layers) override {
    for (std::uint32_t i = 0; i < layerCount(); ++i) appendLayer(enc_[i], changed_[i], layers);
  }

 private:
  void start(const std::uint8_t* item, std::uint32_t context) {
    std::uint16_t value[4] = {};
    std::memcpy(value, item, nir_ ? 8 : 6);
    contexts_.start(value, context);
  }

  bool nir_;
  ChannelContexts<RgbNirModels, std::uint16_t> contexts_;
  ArithmeticDecoder dec_[2];
  ArithmeticEncoder enc_[2];
  bool changed_[2] = {};
};

struct ByteModels {
  ByteModels(std::size_t size, bool decoder) {
    models.reserve(size);
    for (std::size_t i = 0; i < size; ++i) models.emplace_back(256, decoder);
  }
  void reset() {
    for (auto& m : models) m.reset();
  }
  std::vector<SymbolModel> models;
};

/** BYTE14: one layer per extra byte. */
class Byte14Coder : public LayeredItemCoder {
 public:
  Byte14Coder(std::uint32_t size, bool decoder, bool stale_switch)
      : size_(size),
        contexts_(size, stale_switch,
                  [size, decoder] { return std::make_unique<ByteModels>(size, decoder); }),
        dec_(size),
        enc_(size),
        changed_(size, false) {}
  std::uint32_t layerCount() const override { return size_; }

  void initDecoder(const std::uint8_t* item, const ByteSpan* layers,
                   std::uint32_t& context) override {
    for (std::uint32_t i = 0; i < size_; ++i) {
      changed_[i] = layers[i].size > 0;
      if (changed_[i]) dec_[i].init(layers[i].data, layers[i].data + layers[i].size);
    }
    contexts_.start(item, context);
  }

  void decode(std::uint8_t* item, std::uint32_t& context) override {
    auto [models, last] = contexts_.select(context);
    for (std::uint32_t i = 0; i < size_; ++i) {
      if (changed_[i]) {
        last[i] = static_cast<std::uint8_t>(last[i] + dec_[i].decodeSymbol(models->models[i]));
      }
      item[i] = last[i];
    }
  }

  void initEncoder(const std::uint8_t* item, std::uint32_t& context) override {
    for (std::uint32_t i = 0; i < size_; ++i) {
      enc_[i].init();
      changed_[i] = false;
    }
    contexts_.start(item, context);
  }

  void encode(const std::uint8_t* item, std::uint32_t& context) override {
    auto [models, last] = contexts_.select(context);
    for (std::uint32_t i = 0; i < size_; ++i) {
      const std::int32_t diff = static_cast<std::int32_t>(item[i]) - last[i];
      enc_[i].encodeSymbol(models->models[i], foldByte(diff));
      if (diff) changed_[i] = true;
      last[i] = item[i];
    }
  }

  void finishLayers(std::vector<std::vector<std::uint8_t>>& layers) override {
    for (std::uint32_t i = 0; i < size_; ++i) appendLayer(enc_[i], changed_[i], layers);
  }

 private:
  std::uint32_t size_;
  ChannelContexts<ByteModels, std::uint8_t> contexts_;
  std::vector<ArithmeticDecoder> dec_;
  std::vector<ArithmeticEncoder> enc_;
  std::vector<bool> changed_;
};

}  // namespace

std::unique_ptr<LayeredItemCoder> makeLayeredCoder(const Item& item, bool decoder) {
  const bool stale_switch = item.version == 3;
  switch (item.type) {
    case ItemType::kPoint14:
      return std::make_unique<Point14Coder>(decoder);
    case ItemType::kRgb14:
      return std::make_unique<RgbNir14Coder>(false, decoder, stale_switch);
    case ItemType::kRgbNir14:
      return std::make_unique<RgbNir14Coder>(true, decoder, stale_switch);
    case ItemType::kByte14:
      return std::make_unique<Byte14Coder>(item.size, decoder, stale_switch);
    default:
      return nullptr;
  }
}

}  // namespace laz
}  // namespace detail
}  // namespace pcl_ddg
