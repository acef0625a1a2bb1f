// Numbers in input arguments and in what our styles print: one parsing family and one printer.
// Dependency-free (unit-tested in tests/unit/test_numbers.cpp): used by every fix and compute of the
// overlay, the zones-file parser (physics/zones.h) and the EEPA parameter checks (physics/eepa_law.h).
//
// Parsing: a token is a number only as a whole ("5cm", "1.2.3", "" are not), read by strtod/strtol.
//   scan_real     the whole token is a number; its value may be non-finite ("nan", "inf", "1e999")
//                 or rounded to 0 ("1e-400"): for keywords that name the two faults apart ("is not a
//                 number" / "is outside the allowed range")
//   parse_real    a finite number whose conversion did not overflow or underflow
//   parse_integer a base-10 integer in [lo, hi]
//
// Printing: number(value, kind), %.<digits>g (no trailing zeros) with the digits of the kind of output.
// The digits are part of what the tests and the users' scripts match, so each kind keeps its own:
//   NumberKind::record     10  measurement messages and file headers (fix residence/time, massflow/planes,
//                              squeeze/ledger, outlet/sink, balance/x, compute element/stats), zones files
//   NumberKind::setup       6  fix wall/gran/corotating's set-up and restart messages (mesh geometry)
//   NumberKind::guard       4  fix check/contact's guard and event messages (overlaps, speeds, positions)
//   NumberKind::parameter   -  EEPA parameter checks: up to 7 significant digits as written ("-1e-4",
//                              "-350000", "nan", "inf"), exponent form below 1e-3 and from 1e6
#ifndef TSG_NUMBERS_H
#define TSG_NUMBERS_H

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace tsg {

inline bool scan_real(const char *text, double &value)
{
  if (!text || !*text) return false;
  char *end = nullptr;
  errno = 0;
  value = std::strtod(text, &end);
  return end != text && *end == '\0';
}

inline bool parse_real(const char *text, double &value)
{
  return scan_real(text, value) && errno != ERANGE && std::isfinite(value);
}

inline bool parse_integer(const char *text, long lo, long hi, long &value)
{
  if (!text || !*text) return false;
  char *end = nullptr;
  errno = 0;
  value = std::strtol(text, &end, 10);
  return end != text && *end == '\0' && errno != ERANGE && value >= lo && value <= hi;
}

enum class NumberKind { record, setup, guard, parameter };

namespace detail {

// NumberKind::parameter: the mantissa rounded to 6 decimals, fixed notation, trailing zeros dropped.
inline std::string parameter_number(double x)
{
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (x == 0) return "0";
  int exponent = 0;
  double mantissa = x;
  if (std::fabs(x) < 1e-3 || std::fabs(x) >= 1e6) {
    exponent = static_cast<int>(std::floor(std::log10(std::fabs(x))));
    mantissa = std::round(x / std::pow(10.0, exponent) * 1e6) / 1e6;
    if (std::fabs(mantissa) >= 10) {
      mantissa /= 10;
      ++exponent;
    }
  }
  std::string text = std::to_string(mantissa);  // fixed, six decimals
  text.erase(text.find_last_not_of('0') + 1);
  if (text.back() == '.') text.pop_back();
  return exponent == 0 ? text : text + "e" + std::to_string(exponent);
}

}  // namespace detail

inline std::string number(double value, NumberKind kind = NumberKind::record)
{
  if (kind == NumberKind::parameter) return detail::parameter_number(value);
  const int digits = kind == NumberKind::record ? 10 : (kind == NumberKind::setup ? 6 : 4);
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
  return buffer;
}

}  // namespace tsg

#endif
