// The one writer of text into gnuplot scripts, host::gnuplotQuoted (host/src/core/gnuplot.cpp),
// on any bytes: it either refuses them (std::invalid_argument, whose message holds no control
// byte) or returns them as one single-quoted gnuplot string that cannot become a command:
// the bytes unchanged between the quotes, and among them no quote (the only way out of a
// single-quoted string), no newline or carriage return (a new command), no backquote (a
// shell call), no @ (a macro), no $, ;, backslash or double quote, no control or non-ASCII
// byte. The line "set title <text>\n" built from it is then one command with one string.
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "fvp/host/core/gnuplot.h"

namespace {

[[noreturn]] void fail(const char* why, const std::string& text) {
  std::fprintf(stderr, "fvp fuzz: gnuplotQuoted: %s (%zu bytes)\n", why, text.size());
  std::abort();
}

void checkQuoted(const std::string& text, const std::string& quoted) {
  if (quoted.size() != text.size() + 2 || quoted.front() != '\'' || quoted.back() != '\'' ||
      quoted.compare(1, text.size(), text) != 0)
    fail("the result is not the text in single quotes", text);
  for (const unsigned char c : text) {
    if (c < 0x20 || c >= 0x7f) fail("a control or non-ASCII byte got through", text);
    if (std::string_view("'\"`\\@$;#!{}&|<>^~?*\n\r").find(char(c)) != std::string_view::npos)
      fail("a byte that gnuplot or a shell reads got through", text);
  }
  if (!fvp::host::isGnuplotSafeText(text)) fail("accepted what isGnuplotSafeText refuses", text);
  // As a script line: one command (one newline, at its end), and one string token whose
  // closing quote is the line's last character before the newline.
  const std::string line = "set title " + quoted + "\n";
  if (line.find('\n') != line.size() - 1) fail("the line holds a second command", text);
  if (line.find('\'', 11) != line.size() - 2) fail("the string closes early", text);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::string quoted;
  try {
    quoted = fvp::host::gnuplotQuoted(text);
  } catch (const std::invalid_argument& e) {
    if (fvp::host::isGnuplotSafeText(text)) fail("refused what isGnuplotSafeText accepts", text);
    for (const char* p = e.what(); *p; ++p)
      if ((unsigned char)*p < 0x20 || (unsigned char)*p == 0x7f)
        fail("the refusal's message holds a control byte", text);
    return 0;
  }
  checkQuoted(text, quoted);
  return 0;
}
