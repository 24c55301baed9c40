// The LAZ range coder's cold paths: model updates, raw bits, the encoder's flush and carry, and
// the integer compressor (see laz_arithmetic.h for the format).
#include "laz_arithmetic.h"

namespace pcl_ddg {
namespace detail {
namespace laz {

// ---- models ----

void BitModel::reset() {
  bit_0_count_ = 1;
  bit_count_ = 2;
  bit_0_prob_ = 1u << (kBitLengthShift - 1);
  update_cycle_ = bits_until_update_ = 4;  // frequent updates while the model learns
}

void BitModel::update() {
  if ((bit_count_ += update_cycle_) > kBitMaxCount) {  // halve the counts
    bit_count_ = (bit_count_ + 1) >> 1;
    bit_0_count_ = (bit_0_count_ + 1) >> 1;
    if (bit_0_count_ == bit_count_) ++bit_count_;
  }
  const std::uint32_t scale = 0x80000000u / bit_count_;
  bit_0_prob_ = (bit_0_count_ * scale) >> (31 - kBitLengthShift);
  update_cycle_ = (5 * update_cycle_) >> 2;
  if (update_cycle_ > 64) update_cycle_ = 64;
  bits_until_update_ = update_cycle_;
}

SymbolModel::SymbolModel(std::uint32_t symbols, bool decoder)
    : symbols_(symbols), last_symbol_(symbols - 1) {
  if (decoder && symbols > 16) {
    std::uint32_t table_bits = 3;
    while (symbols > (1u << (table_bits + 2))) ++table_bits;
    table_size_ = 1u << table_bits;
    table_shift_ = kSymbolLengthShift - table_bits;
    decoder_table_.assign(table_size_ + 2, 0);
  }
  distribution_.assign(symbols, 0);
  symbol_count_.assign(symbols, 0);
  reset();
}

void SymbolModel::reset() {
  total_count_ = 0;
  update_cycle_ = symbols_;
  for (auto& count : symbol_count_) count = 1;
  update();
  symbols_until_update_ = update_cycle_ = (symbols_ + 6) >> 1;
}

void SymbolModel::update() {
  if ((total_count_ += update_cycle_) > kSymbolMaxCount) {  // halve the counts
    total_count_ = 0;
    for (auto& count : symbol_count_) total_count_ += (count = (count + 1) >> 1);
  }
  const std::uint32_t scale = 0x80000000u / total_count_;
  std::uint32_t sum = 0;
  if (decoder_table_.empty()) {
    for (std::uint32_t k = 0; k < symbols_; ++k) {
      distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += symbol_count_[k];
    }
  } else {
    std::uint32_t s = 0;
    for (std::uint32_t k = 0; k < symbols_; ++k) {
      distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += symbol_count_[k];
      const std::uint32_t w = distribution_[k] >> table_shift_;
      while (s < w) decoder_table_[++s] = k - 1;
    }
    decoder_table_[0] = 0;
    while (s <= table_size_) decoder_table_[++s] = symbols_ - 1;
  }
  update_cycle_ = (5 * update_cycle_) >> 2;
  const std::uint32_t max_cycle = (symbols_ + 6) << 3;
  if (update_cycle_ > max_cycle) update_cycle_ = max_cycle;
  symbols_until_update_ = update_cycle_;
}

// ---- decoder ----

void ArithmeticDecoder::init(const std::uint8_t* begin, const std::uint8_t* end) {
  next_ = begin;
  end_ = end;
  overrun_ = 0;
  length_ = kMaxLength;
  value_ = 0;
  for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | nextByte();
  // An encoder's first four bytes are always below 2^32 - 1 (value < length is the decoder's
  // invariant; the table lookups rely on it).
  if (value_ == kMaxLength)
    throw LazCorruptData("its arithmetic-coded stream starts with FFFFFFFF");
}

void ArithmeticDecoder::failOverrun() const {
  throw LazCorruptData("its arithmetic-coded data ends before all its points are decoded");
}

std::uint32_t ArithmeticDecoder::readUniform(std::uint32_t bits) {
  const std::uint32_t sym = value_ / (length_ >>= bits);
  value_ -= length_ * sym;
  if (length_ < kMinLength) renormalise();
  return sym;
}

std::uint32_t ArithmeticDecoder::readBits(std::uint32_t bits) {
  if (bits > 19) {  // the product would lose precision: split off the low 16 bits
    const std::uint32_t low = readShort();
    return (readBits(bits - 16) << 16) | low;
  }
  return readUniform(bits);
}

std::uint32_t ArithmeticDecoder::readShort() {
  return readUniform(16) & 0xFFFFu;
}

std::uint32_t ArithmeticDecoder::readInt() {
  const std::uint32_t low = readShort();
  return (readShort() << 16) | low;
}

// ---- encoder ----

void ArithmeticEncoder::init() {
  out_.clear();
  base_ = 0;
  length_ = kMaxLength;
}

void ArithmeticEncoder::done() {
  const std::uint32_t init_base = base_;
  bool another_byte = true;
  if (length_ > 2 * kMinLength) {  // one more byte pins a point in the interval
    base_ += kMinLength;
    length_ = kMinLength >> 1;
  } else {  // two more bytes
    base_ += kMinLength >> 1;
    length_ = kMinLength >> 9;
    another_byte = false;
  }
  if (init_base > base_) propagateCarry();
  renormalise();
  // Zeros for the bytes the decoder reads ahead, so that it stays inside the stream.
  out_.push_back(0);
  out_.push_back(0);
  if (another_byte) out_.push_back(0);
}

void ArithmeticEncoder::propagateCarry() {
  // The interval never leaves [0, 1), so the carry stops inside the bytes written.
  std::size_t p = out_.size();
  while (p > 0 && out_[p - 1] == 0xFF) out_[--p] = 0;
  if (p > 0) ++out_[p - 1];
}

void ArithmeticEncoder::writeBits(std::uint32_t bits, std::uint32_t sym) {
  if (bits > 19) {
    writeShort(sym & 0xFFFFu);
    sym >>= 16;
    bits -= 16;
  }
  const std::uint32_t init_base = base_;
  base_ += sym * (length_ >>= bits);
  if (init_base > base_) propagateCarry();
  if (length_ < kMinLength) renormalise();
}

void ArithmeticEncoder::writeShort(std::uint32_t sym) {
  writeBits(16, sym & 0xFFFFu);
}

void ArithmeticEncoder::writeInt(std::uint32_t sym) {
  writeShort(sym & 0xFFFFu);
  writeShort(sym >> 16);
}

// ---- integer compressor ----

IntegerCompressor::IntegerCompressor(std::uint32_t bits, std::uint32_t contexts, bool decoder,
                                     std::uint32_t bits_high)
    : bits_high_(bits_high) {
  if (bits > 0 && bits < 32) {
    corr_bits_ = bits;
    corr_range_ = 1u << bits;
    corr_min_ = -static_cast<std::int32_t>(corr_range_ / 2);
    corr_max_ = corr_min_ + static_cast<std::int32_t>(corr_range_ - 1);
  } else {  // 32 bits: the corrector wraps naturally
    corr_bits_ = 32;
    corr_range_ = 0;
    corr_min_ = INT32_MIN;
    corr_max_ = INT32_MAX;
  }
  k_models_.reserve(contexts);
  for (std::uint32_t i = 0; i < contexts; ++i) k_models_.emplace_back(corr_bits_ + 1, decoder);
  corrector_models_.reserve(corr_bits_);
  for (std::uint32_t k = 1; k <= corr_bits_; ++k)
    corrector_models_.emplace_back(k <= bits_high_ ? 1u << k : 1u << bits_high_, decoder);
}

void IntegerCompressor::reset() {
  k_ = 0;
  for (auto& m : k_models_) m.reset();
  corrector0_.reset();
  for (auto& m : corrector_models_) m.reset();
}

void IntegerCompressor::compress(ArithmeticEncoder& enc, std::int32_t pred, std::int32_t real,
                                 std::uint32_t context) {
  std::int32_t corr = static_cast<std::int32_t>(static_cast<std::uint32_t>(real) -
                                                static_cast<std::uint32_t>(pred));
  if (corr < corr_min_) {
    corr = static_cast<std::int32_t>(static_cast<std::uint32_t>(corr) + corr_range_);
  } else if (corr > corr_max_) {
    corr = static_cast<std::int32_t>(static_cast<std::uint32_t>(corr) - corr_range_);
  }
  writeCorrector(enc, corr, k_models_[context]);
}

void IntegerCompressor::writeCorrector(ArithmeticEncoder& enc, std::int32_t c,
                                       SymbolModel& k_model) {
  // The tightest [-(2^k - 1), 2^k] that holds c: k bits of |c| (of c - 1 when c > 0).
  const std::uint32_t uc = static_cast<std::uint32_t>(c);
  std::uint32_t c1 = c <= 0 ? 0u - uc : uc - 1;
  k_ = 0;
  while (c1) {
    c1 >>= 1;
    ++k_;
  }
  enc.encodeSymbol(k_model, k_);
  if (k_ == 0) {
    enc.encodeBit(corrector0_, uc);
    return;
  }
  if (k_ >= 32) return;                                      // c = -2^31, implied by k
  std::uint32_t v = c < 0 ? uc + ((1u << k_) - 1) : uc - 1;  // into [0, 2^k)
  if (k_ <= bits_high_) {
    enc.encodeSymbol(corrector_models_[k_ - 1], v);
  } else {
    const std::uint32_t k1 = k_ - bits_high_;
    const std::uint32_t low = v & ((1u << k1) - 1);
    enc.encodeSymbol(corrector_models_[k_ - 1], v >> k1);
    enc.writeBits(k1, low);
  }
}

}  // namespace laz
}  // namespace detail
}  // namespace pcl_ddg
