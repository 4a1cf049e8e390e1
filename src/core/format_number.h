// A double as a message shows it: 6 significant digits, exponent form where that is shorter. Not
// std::to_string, whose fixed "%f" prints 1e300 as 301 digits and 1e-9 as 0.000000.
#pragma once

#include <sstream>
#include <string>

namespace granflow
{
  /// x as `std::ostream` prints it by default (%g: 0.333333, 1e+300, 6.5e-05).
  inline std::string
  format_number(const double x)
  {
    std::ostringstream s;
    s << x;
    return s.str();
  }
} // namespace granflow
