// Numbers in messages: the shortest of fixed or scientific notation at a given number
// of significant digits (iostream's default float format), e.g. 2.5e-07, 1800, 0.3.
#pragma once
#include <iomanip>
#include <sstream>
#include <string>

namespace fdem {

// `precision` significant digits: 4 for progress lines and step sizes, 15 where a value
// from a case file is echoed back (so that it reads as the user wrote it).
inline std::string format_number(double v, int precision = 4) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

}  // namespace fdem
