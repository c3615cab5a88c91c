// polydyn — "%.17g" through the C++ library's std::to_chars (design note in number_format.h).
#include "number_format.h"

#include <charconv>
#include <system_error>

extern "C" int pd_format_g17(double x, char* out) {
  // general format with a precision: the text printf("%.17g") writes (C++17 [charconv.to.chars])
  std::to_chars_result r = std::to_chars(out, out + PD_G17_MAX - 1, x, std::chars_format::general, 17);
  if (r.ec != std::errc()) return 0;  // cannot happen: 24 characters at most, and PD_G17_MAX - 1 are free
  *r.ptr = '\0';
  return static_cast<int>(r.ptr - out);
}
