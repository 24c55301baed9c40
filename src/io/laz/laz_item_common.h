#pragma once
// Helpers shared by the LAZ item coders: little-endian field access, byte folding and clamping,
// the streaming median of the coordinate coders and the return-number context tables.
#include <cstdint>
#include <cstring>
#include <memory>

#include "laz_arithmetic.h"

namespace pcl_ddg {
namespace detail {
namespace laz {

// LAS is little-endian, as are the machines this library targets; memcpy keeps the access
// alignment-free.
template <typename T>
inline T load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
template <typename T>
inline void store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}

/** A value of [-255, 510] taken modulo 256 (LASzip's U8_FOLD). */
inline std::uint8_t foldByte(std::int32_t n) {
  return static_cast<std::uint8_t>(n);
}
/** Clamped to [0, 255] (U8_CLAMP). */
inline std::int32_t clampByte(std::int32_t n) {
  return n <= 0 ? 0 : (n >= 255 ? 255 : n);
}

/** Wrapping 32-bit arithmetic (the formats rely on two's-complement wrap-around). */
inline std::int32_t wrapAdd(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(b));
}
inline std::int32_t wrapSub(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b));
}
inline std::int32_t wrapMul(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) * static_cast<std::uint32_t>(b));
}

/** Median of the last five values, updated in O(1) (LASzip's StreamingMedian5). */
class StreamingMedian5 {
 public:
  void reset() {
    for (auto& v : values_) v = 0;
    high_ = true;
  }
  std::int32_t get() const { return values_[2]; }
  void add(std::int32_t v) {
    if (high_) {
      if (v < values_[2]) {
        values_[4] = values_[3];
        values_[3] = values_[2];
        if (v < values_[0]) {
          values_[2] = values_[1];
          values_[1] = values_[0];
          values_[0] = v;
        } else if (v < values_[1]) {
          values_[2] = values_[1];
          values_[1] = v;
        } else {
          values_[2] = v;
        }
      } else {
        if (v < values_[3]) {
          values_[4] = values_[3];
          values_[3] = v;
        } else {
          values_[4] = v;
        }
        high_ = false;
      }
    } else {
      if (values_[2] < v) {
        values_[0] = values_[1];
        values_[1] = values_[2];
        if (values_[4] < v) {
          values_[2] = values_[3];
          values_[3] = values_[4];
          values_[4] = v;
        } else if (values_[3] < v) {
          values_[2] = values_[3];
          values_[3] = v;
        } else {
          values_[2] = v;
        }
      } else {
        if (values_[1] < v) {
          values_[0] = values_[1];
          values_[1] = v;
        } else {
          values_[0] = v;
        }
        high_ = true;
      }
    }
  }

 private:
  std::int32_t values_[5] = {0, 0, 0, 0, 0};
  bool high_ = true;
};

/** A symbol model created on first use (LASzip creates these lazily; a fresh model and a reset
 *  one behave the same, so reset() just resets those that exist). */
class LazyModel {
 public:
  SymbolModel& get(std::uint32_t symbols, bool decoder) {
    if (!model_) model_ = std::make_unique<SymbolModel>(symbols, decoder);
    return *model_;
  }
  void reset() {
    if (model_) model_->reset();
  }

 private:
  std::unique_ptr<SymbolModel> model_;
};

// Return-number contexts (r = return number, n = number of returns): [n][r]. The tables also
// map invalid combinations to contexts of their own, as files do contain them.
extern const std::uint8_t kNumberReturnMap[8][8];
extern const std::uint8_t kNumberReturnLevel[8][8];
extern const std::uint8_t kNumberReturnMap6[16][16];
extern const std::uint8_t kNumberReturnLevel8[16][16];

// GPS time multiplier coding (shared by GPSTIME11 v2 and POINT14 v3).
constexpr std::int32_t kGpsTimeMulti = 500;
constexpr std::int32_t kGpsTimeMultiMinus = -10;

/** Multiplier of the current to the last time difference, rounded (LASzip's I32_QUANTIZE of a
 *  float quotient), clamped where the float would not fit an int32. */
inline std::int32_t gpsTimeMultiplier(std::int32_t diff, std::int32_t last_diff) {
  const float multi = static_cast<float>(diff) / static_cast<float>(last_diff);
  if (!(multi < 2.0e9f)) return INT32_MAX;  // positive overflow (NaN cannot occur: last_diff != 0)
  if (multi <= -2.0e9f) return INT32_MIN + 1;
  return multi >= 0 ? static_cast<std::int32_t>(multi + 0.5f)
                    : static_cast<std::int32_t>(multi - 0.5f);
}

/**
 * The GPS time coder of GPSTIME11 v2 and POINT14 v3: times are coded on their bit patterns as
 * integers, as differences to the last time of one of four interleaved sequences. A difference
 * is coded against a multiple of the sequence's last difference (symbols 0..500 for multipliers
 * 0..500, 501..510 for -1..-10; multipliers beyond become the new base after four in a row); a
 * time that fits no sequence restarts one with its raw 64 bits. Version 2 codes "unchanged" as a
 * symbol of its own; in version 3 a flag of the point does, so its symbols move down by one.
 */
class GpsTimeCoder {
 public:
  GpsTimeCoder(bool with_unchanged, bool decoder)
      : unchanged_(with_unchanged ? 1u : 0u),
        multi_model_(kGpsTimeMulti - kGpsTimeMultiMinus + 5 + unchanged_, decoder),
        zero_diff_model_(5 + unchanged_, decoder),
        ic_(32, 9, decoder) {}

  void reset(std::uint64_t first_time) {
    last_ = next_ = 0;
    for (int i = 0; i < 4; ++i) {
      time_[i] = 0;
      last_diff_[i] = 0;
      extreme_[i] = 0;
    }
    time_[0] = first_time;
    multi_model_.reset();
    zero_diff_model_.reset();
    ic_.reset();
  }
  std::uint64_t time() const { return time_[last_]; }

  /** Decodes the next time (which may equal the last in version 2). */
  std::uint64_t decode(ArithmeticDecoder& dec) {
    const std::uint32_t full = kMultiFull + unchanged_;
    // A switch of sequence decodes again; an encoder switches at most once per time.
    for (int switches = 0;; ++switches) {
      if (switches > 3) throw LazCorruptData("its GPS times switch sequence repeatedly");
      if (last_diff_[last_] == 0) {
        const std::uint32_t sym = dec.decodeSymbol(zero_diff_model_);
        if (sym == unchanged_) {  // a 32-bit difference
          last_diff_[last_] = ic_.decompress(dec, 0, 0);
          time_[last_] += static_cast<std::uint64_t>(static_cast<std::int64_t>(last_diff_[last_]));
          extreme_[last_] = 0;
        } else if (sym == unchanged_ + 1) {
          restart(dec);
        } else if (sym > unchanged_ + 1) {
          last_ = (last_ + sym - (unchanged_ + 1)) & 3;
          continue;
        }  // else: version 2's "unchanged"
      } else {
        const std::uint32_t sym = dec.decodeSymbol(multi_model_);
        if (sym < kMultiFull) {
          const std::int32_t diff = decodeMultiple(dec, static_cast<std::int32_t>(sym));
          time_[last_] += static_cast<std::uint64_t>(static_cast<std::int64_t>(diff));
        } else if (sym == full) {
          restart(dec);
        } else if (sym > full) {
          last_ = (last_ + sym - full) & 3;
          continue;
        }  // else: version 2's "unchanged"
      }
      return time_[last_];
    }
  }

  /** Encodes `time` (version 3 callers only pass times that changed). */
  void encode(ArithmeticEncoder& enc, std::uint64_t time) {
    const std::uint32_t full = kMultiFull + unchanged_;
    for (;;) {
      const bool zero = last_diff_[last_] == 0;
      if (time == time_[last_]) {  // only version 2 gets here
        enc.encodeSymbol(zero ? zero_diff_model_ : multi_model_, zero ? 0 : kMultiFull);
        return;
      }
      const std::int64_t diff64 = static_cast<std::int64_t>(time - time_[last_]);
      if (fits32(diff64)) {
        const std::int32_t diff = static_cast<std::int32_t>(diff64);
        if (zero) {
          enc.encodeSymbol(zero_diff_model_, unchanged_);
          ic_.compress(enc, 0, diff, 0);
          last_diff_[last_] = diff;
          extreme_[last_] = 0;
        } else {
          encodeMultiple(enc, diff);
        }
      } else {
        int other = 0;  // another sequence within 32 bits?
        for (int i = 1; i < 4 && other == 0; ++i) {
          if (fits32(static_cast<std::int64_t>(time - time_[(last_ + i) & 3]))) other = i;
        }
        if (other > 0) {
          enc.encodeSymbol(zero ? zero_diff_model_ : multi_model_,
                           (zero ? unchanged_ + 1 : full) + static_cast<std::uint32_t>(other));
          last_ = (last_ + other) & 3;
          continue;
        }
        enc.encodeSymbol(zero ? zero_diff_model_ : multi_model_, zero ? unchanged_ + 1 : full);
        ic_.compress(enc, static_cast<std::int32_t>(time_[last_] >> 32),
                     static_cast<std::int32_t>(time >> 32), 8);
        enc.writeInt(static_cast<std::uint32_t>(time));
        next_ = (next_ + 1) & 3;
        last_ = next_;
        last_diff_[last_] = 0;
        extreme_[last_] = 0;
      }
      time_[last_] = time;
      return;
    }
  }

 private:
  static constexpr std::uint32_t kMultiFull = kGpsTimeMulti - kGpsTimeMultiMinus + 1;  // 511
  static bool fits32(std::int64_t v) { return v == static_cast<std::int32_t>(v); }

  void restart(ArithmeticDecoder& dec) {
    next_ = (next_ + 1) & 3;
    const std::uint32_t high = static_cast<std::uint32_t>(
        ic_.decompress(dec, static_cast<std::int32_t>(time_[last_] >> 32), 8));
    time_[next_] = (static_cast<std::uint64_t>(high) << 32) | dec.readInt();
    last_ = next_;
    last_diff_[last_] = 0;
    extreme_[last_] = 0;
  }

  /** After an extreme multiplier four times in a row, the difference becomes the new base. */
  void countExtreme(std::int32_t diff) {
    if (++extreme_[last_] > 3) {
      last_diff_[last_] = diff;
      extreme_[last_] = 0;
    }
  }

  std::int32_t decodeMultiple(ArithmeticDecoder& dec, std::int32_t multi) {
    const std::int32_t base = last_diff_[last_];
    std::int32_t diff;
    if (multi == 1) {
      diff = ic_.decompress(dec, base, 1);
      extreme_[last_] = 0;
    } else if (multi == 0) {
      diff = ic_.decompress(dec, 0, 7);
      countExtreme(diff);
    } else if (multi < kGpsTimeMulti) {
      diff = ic_.decompress(dec, wrapMul(multi, base), multi < 10 ? 2 : 3);
    } else if (multi == kGpsTimeMulti) {
      diff = ic_.decompress(dec, wrapMul(kGpsTimeMulti, base), 4);
      countExtreme(diff);
    } else {
      multi = kGpsTimeMulti - multi;
      if (multi > kGpsTimeMultiMinus) {
        diff = ic_.decompress(dec, wrapMul(multi, base), 5);
      } else {
        diff = ic_.decompress(dec, wrapMul(kGpsTimeMultiMinus, base), 6);
        countExtreme(diff);
      }
    }
    return diff;
  }

  void encodeMultiple(ArithmeticEncoder& enc, std::int32_t diff) {
    const std::int32_t base = last_diff_[last_];
    const std::int32_t multi = gpsTimeMultiplier(diff, base);
    if (multi == 1) {
      enc.encodeSymbol(multi_model_, 1);
      ic_.compress(enc, base, diff, 1);
      extreme_[last_] = 0;
    } else if (multi > 0) {
      if (multi < kGpsTimeMulti) {
        enc.encodeSymbol(multi_model_, static_cast<std::uint32_t>(multi));
        ic_.compress(enc, wrapMul(multi, base), diff, multi < 10 ? 2 : 3);
      } else {
        enc.encodeSymbol(multi_model_, kGpsTimeMulti);
        ic_.compress(enc, wrapMul(kGpsTimeMulti, base), diff, 4);
        countExtreme(diff);
      }
    } else if (multi < 0) {
      if (multi > kGpsTimeMultiMinus) {
        enc.encodeSymbol(multi_model_, static_cast<std::uint32_t>(kGpsTimeMulti - multi));
        ic_.compress(enc, wrapMul(multi, base), diff, 5);
      } else {
        enc.encodeSymbol(multi_model_, kGpsTimeMulti - kGpsTimeMultiMinus);
        ic_.compress(enc, wrapMul(kGpsTimeMultiMinus, base), diff, 6);
        countExtreme(diff);
      }
    } else {
      enc.encodeSymbol(multi_model_, 0);
      ic_.compress(enc, 0, diff, 7);
      countExtreme(diff);
    }
  }

  std::uint32_t unchanged_;
  SymbolModel multi_model_, zero_diff_model_;
  IntegerCompressor ic_;
  std::uint32_t last_ = 0, next_ = 0;
  std::uint64_t time_[4] = {};
  std::int32_t last_diff_[4] = {};
  std::int32_t extreme_[4] = {};
};

}  // namespace laz
}  // namespace detail
}  // namespace pcl_ddg
