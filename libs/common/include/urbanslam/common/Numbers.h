#pragma once
// Strict parsing of the numbers in the text formats we read (CARMEN, gfs, Victoria Park, g2o,
// TORO, TUM, relations, ini files, models). strtod and istream also take hexadecimal
// ("0x7fffffff"), "inf", "nan" and values that overflow to infinity: in a log these are always
// corruption, and they reached the filter as huge or non-finite numbers far from the line that
// held them.
#include <optional>
#include <string_view>

namespace urbanslam::common {

// Largest |value| of a position (m) or an angle (rad) any reader accepts. The world of a 2D map
// is far smaller; beyond this a pose's products and differences lose every digit of precision.
constexpr double kMaxCoordinate = 1e7;
// Largest |value| of any other number (times in s, ranges, speeds, matrix entries).
constexpr double kMaxMagnitude = 1e12;

// A finite decimal number: optional sign, digits with at most one '.', optional exponent
// ("-12", "3.5", ".5", "1e-3", "+2.5E+04"). Nothing else, not even surrounding white space.
std::optional<double> parseDecimal(std::string_view text);
// A decimal whole number that fits a long (optional sign and digits only).
std::optional<long> parseWholeNumber(std::string_view text);

}  // namespace urbanslam::common
