#include <penumbra/error.h>

#include <fmt/core.h>

#include <cstdio>

namespace penumbra {

std::string FileLoc::str() const {
  if (!filename) return "";
  return fmt::format("{}:{}:{}", *filename, line, column);
}

// Quotes line `loc.line` of the source with a caret under the column (Tungsten's habit).
static std::string quote_source(const FileLoc& loc) {
  if (!loc.source || loc.line <= 0) return "";
  const std::string& text = *loc.source;
  size_t start = 0;
  for (int l = 1; l < loc.line; ++l) {
    start = text.find('\n', start);
    if (start == std::string::npos) return "";
    ++start;
  }
  size_t end = text.find('\n', start);
  std::string line = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::string caret;
  for (int c = 1; c < loc.column && c - 1 < static_cast<int>(line.size()); ++c)
    caret += line[c - 1] == '\t' ? '\t' : ' ';
  return fmt::format("\n    {}\n    {}^", line, caret);
}

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
