// Numbers as fvp reads them from every file and option: decimal only.
#pragma once

#include <string>

namespace fvp::host {

/// Whether `text` is a number as fvp reads numbers from every file and option: decimal only
/// (an optional '-', digits without a leading zero, an optional fraction and exponent: 2,
/// -0.5, .5, 1e-3), so that `012` (octal 10 to yaml-cpp and strtol), `0x05`, `+5`, ` 5`,
/// `5 ` and `1_000` are refused everywhere alike. integer: no fraction or exponent.
inline bool isDecimalNumberText(const std::string& text, bool integer) {
  std::size_t i = text.empty() || text[0] != '-' ? 0 : 1;
  const auto digits = [&] {
    const std::size_t from = i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i;
    return i - from;
  };
  const std::size_t first = i, whole = digits();
  if (whole > 1 && text[first] == '0') return false;
  std::size_t fraction = 0;
  if (!integer && i < text.size() && text[i] == '.') {
    ++i;
    fraction = digits();
  }
  if (whole + fraction == 0) return false;
  if (!integer && i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    if (digits() == 0) return false;
  }
  return i == text.size();
}

}  // namespace fvp::host
