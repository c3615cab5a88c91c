// polydyn — "%.17g" through double-conversion (design note in number_format.h).
#include "number_format.h"

#include <double-conversion/double-to-string.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace {

// True when |x|'s exact decimal expansion has exactly 18 significant digits: then it lies halfway between
// two 17-digit numbers. x = m·2^-k with m odd has the k-digit fraction m·5^k / 10^k, whose significant
// digits are those of m·5^k; with k <= 0, x is an even integer or one of at most 16 digits: never a tie.
bool is_17_digit_tie(double x) {
  int e;
  double f = std::frexp(std::fabs(x), &e);  // |x| = f·2^e, f in [0.5, 1)
  uint64_t m = static_cast<uint64_t>(std::ldexp(f, 53));
  int k = 53 - e;
  while (m != 0 && (m & 1u) == 0 && k > 0) m >>= 1, --k;
  if (k <= 0 || m == 0) return false;
  const uint64_t lo = 100000000000000000ull, hi = 1000000000000000000ull;  // 10^17, 10^18
  for (int i = 0; i < k; ++i) {
    if (m >= hi / 5) return false;  // more than 18 digits
    m *= 5;
  }
  return m >= lo && m < hi;
}

// The 17 significant digits of x, correctly rounded with ties to even; *point is the decimal exponent of
// the first digit plus one (digits "12", point 1: 1.2). Returns the count without trailing zeros.
int significant_digits(double x, char* digits, int size, bool* sign, int* point) {
  using double_conversion::DoubleToStringConverter;
  int length;
  if (!is_17_digit_tie(x)) {
    DoubleToStringConverter::DoubleToAscii(x, DoubleToStringConverter::PRECISION, 17, digits, size, sign, &length,
                                           point);
  } else {
    // the 18 digits are exact: drop the final 5 and round the 17th to even
    DoubleToStringConverter::DoubleToAscii(x, DoubleToStringConverter::PRECISION, 18, digits, size, sign, &length,
                                           point);
    length = 17;
    if ((digits[16] - '0') % 2 == 1) {
      int i = 16;
      while (i >= 0 && digits[i] == '9') digits[i--] = '0';
      if (i >= 0) {
        ++digits[i];
      } else {
        digits[0] = '1';
        ++*point;
      }
    }
  }
  while (length > 1 && digits[length - 1] == '0') --length;
  return length;
}

}  // namespace

extern "C" int pd_format_g17(double x, char* out) {
  char digits[20];
  bool sign;
  int point;
  int length = significant_digits(x, digits, sizeof digits, &sign, &point);
  char* p = out;
  if (sign) *p++ = '-';
  int exponent = point - 1;
  if (x == 0.0) {
    *p++ = '0';
  } else if (exponent < -4 || exponent >= 17) {  // %g's style e: d.ddde±XX
    *p++ = digits[0];
    if (length > 1) {
      *p++ = '.';
      std::memcpy(p, digits + 1, static_cast<size_t>(length - 1));
      p += length - 1;
    }
    *p++ = 'e';
    *p++ = exponent < 0 ? '-' : '+';
    int e = std::abs(exponent);
    if (e >= 100) *p++ = static_cast<char>('0' + e / 100);
    *p++ = static_cast<char>('0' + e / 10 % 10);
    *p++ = static_cast<char>('0' + e % 10);
  } else if (point <= 0) {  // 0.000ddd
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -point; ++i) *p++ = '0';
    std::memcpy(p, digits, static_cast<size_t>(length));
    p += length;
  } else if (length <= point) {  // ddd000
    std::memcpy(p, digits, static_cast<size_t>(length));
    p += length;
    for (int i = length; i < point; ++i) *p++ = '0';
  } else {  // ddd.ddd
    std::memcpy(p, digits, static_cast<size_t>(point));
    p += point;
    *p++ = '.';
    std::memcpy(p, digits + point, static_cast<size_t>(length - point));
    p += length - point;
  }
  *p = '\0';
  return static_cast<int>(p - out);
}
