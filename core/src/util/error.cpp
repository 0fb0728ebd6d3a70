#include <penumbra/error.h>

#include <fmt/core.h>

#include <algorithm>
#include <cstdio>

namespace penumbra {

std::string FileLoc::str() const {
  if (!filename) return "";
  return fmt::format("{}:{}:{}", *filename, line, column);
}

namespace {

// At most this many bytes of a line are quoted: a 10 MB line with an error at its end prints a
// window around the column, not the line.
constexpr size_t kQuoteWidth = 200;

bool is_continuation(unsigned char c) { return (c & 0xC0) == 0x80; }

// Text that is safe and meaningful to print: valid UTF-8 with no control characters but tabs.
// Anything else (a binary file, escape sequences that would drive the terminal) is not quoted.
bool printable_utf8(const std::string& s) {
  for (size_t i = 0; i < s.size();) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if ((c < 0x20 && c != '\t') || c == 0x7f) return false;
      ++i;
      continue;
    }
    size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
    if (n == 0 || (n == 4 && c > 0xF4) || i + n > s.size()) return false;
    for (size_t k = 1; k < n; ++k)
      if (!is_continuation(static_cast<unsigned char>(s[i + k]))) return false;
    i += n;
  }
  return true;
}

// Quotes line `loc.line` of the source with a caret under the column (Tungsten's habit): the
// whole line when it is short, else kQuoteWidth bytes around the column between "...". A window
// that is not printable UTF-8 is not quoted at all.
std::string quote_source(const FileLoc& loc) {
  if (!loc.source || loc.line <= 0 || loc.column <= 0) return "";
  const std::string& text = *loc.source;
  size_t start = 0;
  for (int l = 1; l < loc.line; ++l) {
    start = text.find('\n', start);
    if (start == std::string::npos) return "";
    ++start;
  }
  size_t end = text.find('\n', start);
  if (end == std::string::npos) end = text.size();
  if (end > start && text[end - 1] == '\r') --end;
  if (loc.line == 1 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) start = std::min<size_t>(3, end);
  // The byte under the caret (the tokenizer counts columns after a byte-order mark).
  size_t column = start + static_cast<size_t>(loc.column) - 1;
  column = std::min(column, end);
  size_t from = start, to = end;
  if (end - start > kQuoteWidth) {
    from = column >= start + kQuoteWidth / 2 ? column - kQuoteWidth / 2 : start;
    to = std::min(end, from + kQuoteWidth);
    from = to - kQuoteWidth;  // a full window also near the end of the line (end - start > width)
    while (from > start && is_continuation(static_cast<unsigned char>(text[from]))) --from;
    while (to < end && is_continuation(static_cast<unsigned char>(text[to]))) ++to;
  }
  std::string window = text.substr(from, to - from);
  if (!printable_utf8(window)) return "";
  std::string before = from > start ? "..." : "";
  std::string after = to < end ? "..." : "";
  // One space per character before the column (tabs copied, so the caret lines up under them).
  std::string caret(before.size(), ' ');
  for (size_t i = from; i < column && i < to; ++i) {
    unsigned char c = static_cast<unsigned char>(text[i]);
    if (is_continuation(c)) continue;
    caret += c == '\t' ? '\t' : ' ';
  }
  return fmt::format("\n    {}{}{}\n    {}^", before, window, after, caret);
}

}  // namespace

std::string Error::formatted() const {
  std::string where = loc_.str();
  if (where.empty()) return fmt::format("error: {}", what());
  return fmt::format("{}: error: {}{}", where, what(), quote_source(loc_));
}

void warning(const FileLoc& loc, const std::string& message) {
  std::string where = loc.str();
  if (where.empty())
    std::fprintf(stderr, "warning: %s\n", message.c_str());
  else
    std::fprintf(stderr, "%s: warning: %s\n", where.c_str(), message.c_str());
}

}  // namespace penumbra
