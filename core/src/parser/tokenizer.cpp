#include "parser/tokenizer.h"

#include <fmt/core.h>

#include <cctype>
#include <charconv>
#include <cmath>

namespace penumbra {

namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}
bool is_word_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_number_start(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.';
}
// A number runs to the next separator, so "1.2.3" or "1e" stay one token and the parser can report
// the whole bad number instead of a confusing split.
bool ends_number(char c) { return is_space(c) || c == '[' || c == ']' || c == '"' || c == '#'; }

std::string describe_char(char c) {
  auto u = static_cast<unsigned char>(c);
  if (std::isprint(u)) return fmt::format("'{}'", c);
  return fmt::format("byte 0x{:02x}", u);
}

}  // namespace

Tokenizer::Tokenizer(std::shared_ptr<const std::string> text,
                     std::shared_ptr<const std::string> filename)
    : text_(std::move(text)), filename_(std::move(filename)) {
  // A UTF-8 byte-order mark (editors on Windows write one) is skipped; columns count after it.
  if (text_->compare(0, 3, "\xEF\xBB\xBF") == 0) pos_ = 3;
}

FileLoc Tokenizer::here() const { return FileLoc{filename_, text_, line_, column_}; }

void Tokenizer::advance() {
  if ((*text_)[pos_] == '\n') {
    ++line_;
    column_ = 1;
  } else {
    ++column_;
  }
  ++pos_;
}

Token Tokenizer::next() {
  if (has_peeked_) {
    has_peeked_ = false;
    return std::move(peeked_);
  }
  return scan();
}

const Token& Tokenizer::peek() {
  if (!has_peeked_) {
    peeked_ = scan();
    has_peeked_ = true;
  }
  return peeked_;
}

void Tokenizer::skip_space_and_comments() {
  const std::string& s = *text_;
  while (pos_ < s.size()) {
    if (is_space(s[pos_])) {
      advance();
    } else if (s[pos_] == '#') {
      while (pos_ < s.size() && s[pos_] != '\n') advance();
    } else {
      return;
    }
  }
}

Token Tokenizer::scan() {
  skip_space_and_comments();
  const std::string& s = *text_;
  if (pos_ >= s.size()) return Token{TokenKind::End, "", here()};
  char c = s[pos_];
  if (c == '"') return scan_string();
  if (c == '[' || c == ']') {
    Token t{c == '[' ? TokenKind::LBracket : TokenKind::RBracket, std::string(1, c), here()};
    advance();
    return t;
  }
  if (is_word_start(c)) return scan_run(TokenKind::Word);
  if (is_number_start(c)) return scan_run(TokenKind::Number);
  throw Error(here(), fmt::format("unexpected character {}", describe_char(c)));
}

Token Tokenizer::scan_run(TokenKind kind) {
  const std::string& s = *text_;
  Token t{kind, "", here()};
  size_t start = pos_;
  while (pos_ < s.size() &&
         (kind == TokenKind::Word ? is_word_char(s[pos_]) : !ends_number(s[pos_])))
    advance();
  t.text = s.substr(start, pos_ - start);
  return t;
}

Token Tokenizer::scan_string() {
  const std::string& s = *text_;
  Token t{TokenKind::String, "", here()};
  advance();  // opening quote
  while (pos_ < s.size() && s[pos_] != '"') {
    // pbrt strings never span lines; stopping here points the user at the missing quote.
    if (s[pos_] == '\n') break;
    if (s[pos_] != '\\') {
      t.text += s[pos_];
      advance();
      continue;
    }
    FileLoc escape_loc = here();
    advance();
    if (pos_ >= s.size() || s[pos_] == '\n') break;
    switch (s[pos_]) {
      case '"': t.text += '"'; break;
      case '\\': t.text += '\\'; break;
      case '\'': t.text += '\''; break;
      case 'n': t.text += '\n'; break;
      case 't': t.text += '\t'; break;
      case 'r': t.text += '\r'; break;
      case 'b': t.text += '\b'; break;
      case 'f': t.text += '\f'; break;
      default:
        throw Error(escape_loc, fmt::format("unknown escape sequence '\\{}' in string", s[pos_]));
    }
    advance();
  }
  if (pos_ >= s.size() || s[pos_] != '"') throw Error(t.loc, "unterminated string");
  advance();  // closing quote
  return t;
}

std::string shorten(const std::string& text, size_t max) {
  if (text.size() <= max) return text;
  size_t cut = max;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8 characters
  return fmt::format("{}... ({} bytes)", text.substr(0, cut), text.size());
}

std::string describe(const Token& t) {
  switch (t.kind) {
    case TokenKind::String: return fmt::format("string \"{}\"", shorten(t.text));
    case TokenKind::End: return "end of file";
    default: return fmt::format("'{}'", shorten(t.text));
  }
}

double parse_number(const Token& t) {
  if (t.kind != TokenKind::Number)
    throw Error(t.loc, fmt::format("expected a number, got {}", describe(t)));
  const char* first = t.text.data();
  const char* last = first + t.text.size();
  // from_chars rejects a leading '+', which pbrt files may contain.
  if (last - first > 1 && *first == '+' && first[1] != '-') ++first;
  double v = 0.0;
  auto [end, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || end != last || first == last || !std::isfinite(v))
    throw Error(t.loc, fmt::format("bad number '{}'", shorten(t.text)));
  return v;
}

}  // namespace penumbra
