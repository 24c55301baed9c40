#include "byte_cursor.h"

#include <pcl/PCLPointField.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <sstream>

namespace pcl_ddg {
namespace detail {
namespace {

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

}  // namespace

std::string_view ByteCursor::token() {
  while (pos_ < data_.size() && isSpace(data_[pos_])) ++pos_;
  const std::size_t start = pos_;
  while (pos_ < data_.size() && !isSpace(data_[pos_])) ++pos_;
  return data_.substr(start, pos_ - start);
}

std::string_view ByteCursor::requireToken(const char* what) {
  const std::string_view t = token();
  if (t.empty()) fail(std::string("unexpected end of file while reading ") + what);
  return t;
}

std::string_view ByteCursor::line() {
  const std::size_t start = pos_;
  const std::size_t newline = data_.find('\n', pos_);
  const std::size_t end = newline == std::string_view::npos ? data_.size() : newline;
  pos_ = newline == std::string_view::npos ? data_.size() : newline + 1;
  std::string_view text = data_.substr(start, end - start);
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  return text;
}

bool ByteCursor::lineEnded() {
  while (pos_ < data_.size() && data_[pos_] != '\n' && isSpace(data_[pos_])) ++pos_;
  return pos_ >= data_.size() || data_[pos_] == '\n';
}

double ByteCursor::parseDouble(std::string_view t, const char* what) const {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec == std::errc::result_out_of_range) {
    // Overflow or underflow: strtod gives the IEEE answer (inf or a denormal/zero).
    return std::strtod(std::string(t).c_str(), nullptr);
  }
  if (ec != std::errc() || end != t.data() + t.size()) {
    // from_chars rejects "nan"/"inf" spellings such as "-nan" or "+inf"; accept them via strtod.
    const std::string s(t);
    char* s_end = nullptr;
    const double v = std::strtod(s.c_str(), &s_end);
    if (s_end != s.c_str() + s.size()) {
      fail(std::string("expected a number for ") + what + ", found '" + s.substr(0, 40) + "'");
    }
    return v;
  }
  return value;
}

std::int64_t ByteCursor::parseInt(std::string_view t, const char* what) const {
  std::int64_t value = 0;
  const char* first = t.data();
  if (!t.empty() && t.front() == '+') ++first;
  const auto [end, ec] = std::from_chars(first, t.data() + t.size(), value);
  if (ec != std::errc() || end != t.data() + t.size()) {
    fail(std::string("expected an integer for ") + what + ", found '" +
         std::string(t.substr(0, 40)) + "'");
  }
  return value;
}

const char* ByteCursor::take(std::size_t n, const char* what) {
  if (n > remaining()) fail(std::string("unexpected end of file while reading ") + what);
  const char* p = data_.data() + pos_;
  pos_ += n;
  return p;
}

std::size_t ByteCursor::lineNumber(std::size_t offset) const {
  if (outer_ != nullptr)
    return outer_->lineNumber(static_cast<std::size_t>(data_.data() - outer_->data_.data()));
  const std::size_t upto = std::min(offset, data_.size());
  return 1 + static_cast<std::size_t>(std::count(
                 data_.begin(), data_.begin() + static_cast<std::ptrdiff_t>(upto), '\n'));
}

void ByteCursor::fail(const std::string& message) const {
  throw FileFormatException("line " + std::to_string(lineNumber(pos_)) + ": " + message);
}

void ByteCursor::failOutOfRange(double v, const char* what) const {
  std::ostringstream text;
  text << "value " << v << " is out of range for " << what;
  fail(text.str());
}

void ByteCursor::storeAs(std::uint8_t pcl_datatype, double v, std::uint8_t* dst,
                         const char* what) const {
  switch (pcl_datatype) {
    case pcl::PCLPointField::INT8:
      return store<std::int8_t>(v, dst, what);
    case pcl::PCLPointField::UINT8:
      return store<std::uint8_t>(v, dst, what);
    case pcl::PCLPointField::INT16:
      return store<std::int16_t>(v, dst, what);
    case pcl::PCLPointField::UINT16:
      return store<std::uint16_t>(v, dst, what);
    case pcl::PCLPointField::INT32:
      return store<std::int32_t>(v, dst, what);
    case pcl::PCLPointField::UINT32:
      return store<std::uint32_t>(v, dst, what);
    case pcl::PCLPointField::INT64:
      return store<std::int64_t>(v, dst, what);
    case pcl::PCLPointField::UINT64:
      return store<std::uint64_t>(v, dst, what);
    case pcl::PCLPointField::FLOAT32:
      return store<float>(v, dst, what);
    default:
      return store<double>(v, dst, what);
  }
}

std::int64_t ByteCursor::product(std::int64_t a, std::int64_t b, const char* what) const {
  std::int64_t result = 0;
  if (a < 0 || b < 0 || __builtin_mul_overflow(a, b, &result)) {
    fail(std::string("impossible ") + what + " (" + std::to_string(a) + " x " + std::to_string(b) +
         ")");
  }
  return result;
}

void ByteCursor::reverse(char* bytes, std::size_t n) {
  std::reverse(bytes, bytes + n);
}

}  // namespace detail
}  // namespace pcl_ddg
