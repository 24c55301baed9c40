#pragma once
// A bounds-checked reader over a whole file held in memory, for the text and binary mesh formats.
// Every read past the end or of a malformed number throws FileFormatException with the line.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>

#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {
namespace detail {

enum class ByteOrder { Little, Big };

class ByteCursor {
 public:
  explicit ByteCursor(std::string_view data) : data_(data) {}
  /** A cursor over part of this one's data (one line, say); its errors name the outer line. */
  ByteCursor within(std::string_view part) const {
    ByteCursor inner(part);
    inner.outer_ = this;
    return inner;
  }

  bool atEnd() const { return pos_ >= data_.size(); }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  /** Moves back (or forward) to a position obtained from position(). */
  void seek(std::size_t position) { pos_ = position < data_.size() ? position : data_.size(); }

  /** Next whitespace-separated token; empty at the end of the data. */
  std::string_view token();
  /** Next token, which must exist; `what` names it in the error. */
  std::string_view requireToken(const char* what);
  /** The rest of the current line (without "\r\n"), advancing past it. */
  std::string_view line();
  /** Skips whitespace except newlines, then reports whether the line has ended. */
  bool lineEnded();

  double parseDouble(std::string_view token, const char* what) const;
  std::int64_t parseInt(std::string_view token, const char* what) const;
  double readDouble(const char* what) { return parseDouble(requireToken(what), what); }
  std::int64_t readInt(const char* what) { return parseInt(requireToken(what), what); }

  /** v as a T, refused (with the line) unless the conversion is exact for an integer type (an
   *  integral value in range) or within range for float; a cast outside the range would be
   *  undefined behaviour. */
  template <typename T>
  T convert(double v, const char* what) const {
    if constexpr (std::is_same_v<T, double>) {
      return v;
    } else if constexpr (std::is_floating_point_v<T>) {
      if (std::isfinite(v) && std::abs(v) > static_cast<double>(std::numeric_limits<T>::max()))
        failOutOfRange(v, what);
      return static_cast<T>(v);
    } else {
      const double end = std::ldexp(1.0, std::numeric_limits<T>::digits);  // max() + 1, exact
      const double lowest = std::is_signed_v<T> ? -end : 0.0;
      if (!(v == std::trunc(v) && v >= lowest && v < end)) failOutOfRange(v, what);
      return static_cast<T>(v);
    }
  }
  /** Stores convert<T>(v) at dst. */
  template <typename T>
  void store(double v, std::uint8_t* dst, const char* what) const {
    const T value = convert<T>(v, what);
    std::memcpy(dst, &value, sizeof(T));
  }
  /** Stores v in a field of the given pcl::PCLPointField datatype (convert's checks). */
  void storeAs(std::uint8_t pcl_datatype, double v, std::uint8_t* dst, const char* what) const;
  /** a * b for non-negative counts, refused when it overflows. */
  std::int64_t product(std::int64_t a, std::int64_t b, const char* what) const;

  /** Raw bytes of a T in the given byte order. */
  template <typename T>
  T readBinary(ByteOrder order, const char* what) {
    const char* p = take(sizeof(T), what);
    char bytes[sizeof(T)];
    std::memcpy(bytes, p, sizeof(T));
    if (order == ByteOrder::Big) reverse(bytes, sizeof(T));
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }
  /** Points at the next n bytes and advances past them. */
  const char* take(std::size_t n, const char* what);
  void skip(std::size_t n, const char* what) { take(n, what); }

  /** Throws FileFormatException("line L: message"). */
  [[noreturn]] void fail(const std::string& message) const;

 private:
  [[noreturn]] void failOutOfRange(double v, const char* what) const;
  static void reverse(char* bytes, std::size_t n);
  std::size_t lineNumber(std::size_t offset) const;
  std::string_view data_;
  std::size_t pos_ = 0;
  const ByteCursor* outer_ = nullptr;
};

}  // namespace detail
}  // namespace pcl_ddg
