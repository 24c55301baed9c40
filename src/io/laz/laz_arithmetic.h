#pragma once
/** \file
 * The entropy coder of LAZ (LASzip): a 32-bit range coder after Amir Said's FastAC, with
 * adaptive models, and LASzip's integer compressor built on it.
 *
 * **Range coder.** The coder keeps an interval [base, base + length) of 32-bit integers, initially
 * length = 2^32 - 1. Coding a symbol s with cumulative frequencies F(s) <= F(s+1) (scaled to
 * 2^15 for symbol models, 2^13 for bit models) narrows it to
 *   base += F(s) * (length >> 15),  length = (F(s+1) - F(s)) * (length >> 15)
 * (the last symbol takes the whole rest of the interval). When length drops below 2^24 the top
 * byte of base is emitted and both are shifted left by 8 ("renormalisation"); a carry out of base
 * is propagated into the bytes already emitted. The decoder mirrors this with
 * value = (code - base) and reads one byte per shift. Raw bits are coded with a uniform
 * distribution (length >>= bits). At the end the encoder emits one or two bytes that pin a point
 * inside the final interval and then two or three zero bytes, so that the decoder, which reads
 * four bytes ahead, never reads past the stream.
 *
 * **Adaptive models.** A symbol model with n symbols (2 <= n <= 2048) counts occurrences; every
 * `update_cycle` symbols (growing by 5/4 up to 8 (n + 6)) the cumulative distribution is
 * recomputed, halving all counts once their total exceeds 2^15. Decoders with more than 16
 * symbols also build a lookup table indexed by the top bits of value / length. A bit model does
 * the same with counts capped at 2^13 and a cycle capped at 64.
 *
 * **Integer compressor.** An integer `real` is coded as a corrector c = real - pred (wrapped to
 * the value's bit width). The number k of significant bits of c (0 <= k <= 32: c lies in
 * [-(2^k - 1), -(2^(k-1))] or [2^(k-1) + 1, 2^k]) is coded with a per-context symbol model; then
 * c itself: for k = 0 (c is 0 or 1) with a bit model, for 1 <= k <= 8 with a 2^k-symbol model
 * for that k, for larger k the top 8 bits with a 256-symbol model and the k - 8 low bits raw.
 * k = 32 stands for c = -2^31. These are the streams of the LAZ specification (LASzip 2.0+).
 *
 * Decoding corrupt bytes must never read outside the given range: a decoder that needs more than
 * a few bytes past its end throws LazCorruptData, which the caller turns into a message naming
 * the chunk.
 */
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pcl_ddg {
namespace detail {
namespace laz {

/** Compressed data that cannot be what an encoder wrote (internal; reported per chunk). */
class LazCorruptData : public std::runtime_error {
 public:
  explicit LazCorruptData(const std::string& what) : std::runtime_error(what) {}
};

constexpr std::uint32_t kMinLength = 0x01000000u;  // renormalise below this interval length
constexpr std::uint32_t kMaxLength = 0xFFFFFFFFu;
constexpr std::uint32_t kBitLengthShift = 13;  // bit models: probabilities in 1/2^13
constexpr std::uint32_t kBitMaxCount = 1u << kBitLengthShift;
constexpr std::uint32_t kSymbolLengthShift = 15;  // symbol models: frequencies in 1/2^15
constexpr std::uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;

/** Adaptive model of one binary decision. */
class BitModel {
 public:
  BitModel() { reset(); }
  /** Back to equiprobable, as at the start of every chunk. */
  void reset();
  /** Recomputes the probability of a 0 from the counts (periodically). */
  void update();

  std::uint32_t update_cycle_, bits_until_update_;
  std::uint32_t bit_0_prob_, bit_0_count_, bit_count_;
};

/** Adaptive model of a symbol in [0, symbols). */
class SymbolModel {
 public:
  /** `decoder` builds the lookup table that speeds up decoding of alphabets above 16 symbols. */
  SymbolModel(std::uint32_t symbols, bool decoder);
  /** Back to uniform counts, as at the start of every chunk. */
  void reset();
  /** Recomputes the cumulative distribution (and decoder table) from the counts. */
  void update();

  std::uint32_t symbols_, last_symbol_, table_size_ = 0, table_shift_ = 0;
  std::uint32_t total_count_ = 0, update_cycle_ = 0, symbols_until_update_ = 0;
  std::vector<std::uint32_t> distribution_, symbol_count_, decoder_table_;
};

/** Range decoder over the bytes [begin, end). */
class ArithmeticDecoder {
 public:
  /** Starts decoding at begin: reads the first four bytes. */
  void init(const std::uint8_t* begin, const std::uint8_t* end);

  std::uint32_t decodeBit(BitModel& m);
  std::uint32_t decodeSymbol(SymbolModel& m);
  /** Raw (uniformly coded) bits, 1 <= bits <= 32. */
  std::uint32_t readBits(std::uint32_t bits);
  std::uint32_t readShort();
  /** 32 raw bits: the low 16 first. */
  std::uint32_t readInt();

  /** The next byte not yet read: the end of this stream once decoding is complete. */
  const std::uint8_t* position() const { return next_; }

 private:
  /** Past the end the stream reads as zeros, for a few bytes (an old writer's missing padding);
   *  beyond that the data is corrupt. */
  static constexpr std::uint32_t kOverrunSlack = 4;

  std::uint8_t nextByte() {
    if (next_ < end_) return *next_++;
    if (++overrun_ > kOverrunSlack) failOverrun();
    return 0;
  }
  [[noreturn]] void failOverrun() const;
  void renormalise() {
    do {  // read the next least significant byte
      value_ = (value_ << 8) | nextByte();
    } while ((length_ <<= 8) < kMinLength);
  }
  std::uint32_t readUniform(std::uint32_t bits);

  const std::uint8_t* next_ = nullptr;
  const std::uint8_t* end_ = nullptr;
  std::uint32_t overrun_ = 0;
  std::uint32_t value_ = 0, length_ = kMaxLength;
};

/** Range encoder appending to its own byte buffer. */
class ArithmeticEncoder {
 public:
  /** Starts a new stream (clears the buffer). */
  void init();
  /** Flushes the final bytes; bytes() is then the complete stream. */
  void done();
  const std::vector<std::uint8_t>& bytes() const { return out_; }

  void encodeBit(BitModel& m, std::uint32_t bit);
  void encodeSymbol(SymbolModel& m, std::uint32_t sym);
  void writeBits(std::uint32_t bits, std::uint32_t sym);
  void writeShort(std::uint32_t sym);
  void writeInt(std::uint32_t sym);

 private:
  void propagateCarry();
  void renormalise() {
    do {  // emit the top byte
      out_.push_back(static_cast<std::uint8_t>(base_ >> 24));
      base_ <<= 8;
    } while ((length_ <<= 8) < kMinLength);
  }

  std::vector<std::uint8_t> out_;
  std::uint32_t base_ = 0, length_ = kMaxLength;
};

/** LASzip's IntegerCompressor: integers of `bits` bits coded as corrected predictions. */
class IntegerCompressor {
 public:
  /** `decoder`: whether its symbol models are used for decoding (builds their tables). */
  IntegerCompressor(std::uint32_t bits, std::uint32_t contexts, bool decoder,
                    std::uint32_t bits_high = 8);
  /** Resets all models, as at the start of every chunk. */
  void reset();

  void compress(ArithmeticEncoder& enc, std::int32_t pred, std::int32_t real,
                std::uint32_t context = 0);
  std::int32_t decompress(ArithmeticDecoder& dec, std::int32_t pred, std::uint32_t context = 0);
  /** The bit count k of the last corrector (used as context by the point coders). */
  std::uint32_t k() const { return k_; }

 private:
  std::int32_t readCorrector(ArithmeticDecoder& dec, SymbolModel& k_model);
  void writeCorrector(ArithmeticEncoder& enc, std::int32_t c, SymbolModel& k_model);

  std::uint32_t bits_high_, corr_bits_, corr_range_;
  std::int32_t corr_min_, corr_max_;
  std::uint32_t k_ = 0;
  std::vector<SymbolModel> k_models_;          // per context: k in [0, corr_bits]
  BitModel corrector0_;                        // k = 0
  std::vector<SymbolModel> corrector_models_;  // [k - 1] for 1 <= k <= corr_bits
};

// ---- hot paths, inline ----

inline std::uint32_t ArithmeticDecoder::decodeBit(BitModel& m) {
  const std::uint32_t x = m.bit_0_prob_ * (length_ >> kBitLengthShift);
  const std::uint32_t sym = value_ >= x;
  if (sym == 0) {
    length_ = x;
    ++m.bit_0_count_;
  } else {
    value_ -= x;
    length_ -= x;
  }
  if (length_ < kMinLength) renormalise();
  if (--m.bits_until_update_ == 0) m.update();
  return sym;
}

inline std::uint32_t ArithmeticDecoder::decodeSymbol(SymbolModel& m) {
  std::uint32_t n, sym, x, y = length_;
  const std::uint32_t* dist = m.distribution_.data();
  if (!m.decoder_table_.empty()) {
    // Table lookup narrows the search to a few symbols, bisection finishes it.
    const std::uint32_t dv = value_ / (length_ >>= kSymbolLengthShift);
    std::uint32_t t = dv >> m.table_shift_;
    if (t > m.table_size_) t = m.table_size_;  // only a corrupt stream gets here
    sym = m.decoder_table_[t];
    n = m.decoder_table_[t + 1] + 1;
    while (n > sym + 1) {
      const std::uint32_t k = (sym + n) >> 1;
      if (dist[k] > dv) {
        n = k;
      } else {
        sym = k;
      }
    }
    x = dist[sym] * length_;
    if (sym != m.last_symbol_) y = dist[sym + 1] * length_;
  } else {
    // Small alphabet: bisection with multiplications only.
    x = sym = 0;
    length_ >>= kSymbolLengthShift;
    std::uint32_t k = (n = m.symbols_) >> 1;
    do {
      const std::uint32_t z = length_ * dist[k];
      if (z > value_) {
        n = k;
        y = z;
      } else {
        sym = k;
        x = z;
      }
    } while ((k = (sym + n) >> 1) != sym);
  }
  value_ -= x;
  length_ = y - x;
  if (length_ < kMinLength) renormalise();
  ++m.symbol_count_[sym];
  if (--m.symbols_until_update_ == 0) m.update();
  return sym;
}

inline void ArithmeticEncoder::encodeBit(BitModel& m, std::uint32_t bit) {
  const std::uint32_t x = m.bit_0_prob_ * (length_ >> kBitLengthShift);
  if (bit == 0) {
    length_ = x;
    ++m.bit_0_count_;
  } else {
    const std::uint32_t init_base = base_;
    base_ += x;
    length_ -= x;
    if (init_base > base_) propagateCarry();
  }
  if (length_ < kMinLength) renormalise();
  if (--m.bits_until_update_ == 0) m.update();
}

inline void ArithmeticEncoder::encodeSymbol(SymbolModel& m, std::uint32_t sym) {
  const std::uint32_t init_base = base_;
  if (sym == m.last_symbol_) {
    const std::uint32_t x = m.distribution_[sym] * (length_ >> kSymbolLengthShift);
    base_ += x;
    length_ -= x;
  } else {
    const std::uint32_t x = m.distribution_[sym] * (length_ >>= kSymbolLengthShift);
    base_ += x;
    length_ = m.distribution_[sym + 1] * length_ - x;
  }
  if (init_base > base_) propagateCarry();
  if (length_ < kMinLength) renormalise();
  ++m.symbol_count_[sym];
  if (--m.symbols_until_update_ == 0) m.update();
}

inline std::int32_t IntegerCompressor::decompress(ArithmeticDecoder& dec, std::int32_t pred,
                                                  std::uint32_t context) {
  std::uint32_t real = static_cast<std::uint32_t>(pred) +
                       static_cast<std::uint32_t>(readCorrector(dec, k_models_[context]));
  // Fold back into [0, 2^bits) (a no-op for 32 bits, where corr_range is 0).
  if (static_cast<std::int32_t>(real) < 0) {
    real += corr_range_;
  } else if (real >= corr_range_) {
    real -= corr_range_;
  }
  return static_cast<std::int32_t>(real);
}

inline std::int32_t IntegerCompressor::readCorrector(ArithmeticDecoder& dec, SymbolModel& k_model) {
  k_ = dec.decodeSymbol(k_model);
  if (k_ == 0) return static_cast<std::int32_t>(dec.decodeBit(corrector0_));  // 0 or 1
  if (k_ >= 32) return corr_min_;
  std::uint32_t c;
  if (k_ <= bits_high_) {
    c = dec.decodeSymbol(corrector_models_[k_ - 1]);
  } else {  // the high bits modelled, the low ones raw
    const std::uint32_t k1 = k_ - bits_high_;
    c = dec.decodeSymbol(corrector_models_[k_ - 1]);
    c = (c << k1) | dec.readBits(k1);
  }
  // c is in [0, 2^k): its upper half maps to [2^(k-1) + 1, 2^k], its lower to [-(2^k - 1), ...].
  if (c >= (1u << (k_ - 1))) return static_cast<std::int32_t>(c + 1);
  return static_cast<std::int32_t>(c - ((1u << k_) - 1));
}

}  // namespace laz
}  // namespace detail
}  // namespace pcl_ddg
