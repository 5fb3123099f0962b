#include "urbanslam/common/Numbers.h"

#include <charconv>
#include <cmath>

namespace urbanslam::common {

namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// Length of the run of digits starting at i.
size_t digits(std::string_view s, size_t i) {
  size_t n = 0;
  while (i + n < s.size() && isDigit(s[i + n])) ++n;
  return n;
}

}  // namespace

std::optional<double> parseDecimal(std::string_view s) {
  size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  const size_t sign = i;
  const size_t whole = digits(s, i);
  i += whole;
  size_t fraction = 0;
  if (i < s.size() && s[i] == '.') fraction = digits(s, ++i), i += fraction;
  if (whole + fraction == 0) return std::nullopt;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    const size_t exponent = digits(s, i);
    if (exponent == 0) return std::nullopt;
    i += exponent;
  }
  if (i != s.size()) return std::nullopt;
  // from_chars takes no leading '+'; the grammar above has been checked already.
  const char* first = s.data() + (s[0] == '+' ? sign : 0);
  double v = 0;
  const auto [end, ec] = std::from_chars(first, s.data() + s.size(), v);
  if (ec == std::errc::result_out_of_range) {
    // An underflow to zero is harmless ("1e-400"), an overflow is not a number we can use.
    const size_t e = s.find_first_of("eE");
    if (e != std::string_view::npos && s[e + 1] == '-') return 0.0;
    return std::nullopt;
  }
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<long> parseWholeNumber(std::string_view s) {
  size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  if (digits(s, i) == 0 || i + digits(s, i) != s.size()) return std::nullopt;
  long v = 0;
  const char* first = s.data() + (s[0] == '+' ? 1 : 0);
  const auto [end, ec] = std::from_chars(first, s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

}  // namespace urbanslam::common
