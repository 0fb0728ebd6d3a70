// Splits pbrt-v4 scene text into tokens, each with the line and column it starts at, so every later
// error (a bad value, an unknown directive) can point at the exact spot in the file.
#pragma once

#include <penumbra/error.h>

#include <memory>
#include <string>

namespace penumbra {

enum class TokenKind {
  Word,      // bare word: a directive name, or true/false
  String,    // quoted string; `text` holds the contents with escapes resolved
  Number,    // as written ("1.5", "-3e2"); checked and converted by the parser
  LBracket,  // [
  RBracket,  // ]
  End,       // end of the text
};

struct Token {
  TokenKind kind = TokenKind::End;
  std::string text;
  FileLoc loc;  // where the token starts (the opening quote for strings)
};

/// Reads tokens one at a time. Lines and columns are 1-based; a column counts bytes, so a tab is
/// one column (Error::formatted() copies tabs into the caret line, which keeps the caret aligned).
class Tokenizer {
 public:
  Tokenizer(std::shared_ptr<const std::string> text, std::shared_ptr<const std::string> filename);

  /// The next token, or an End token at the end. Throws Error on an unterminated string or a
  /// character that cannot start a token.
  Token next();
  /// The next token without consuming it.
  const Token& peek();

 private:
  Token scan();
  void skip_space_and_comments();
  Token scan_string();
  Token scan_run(TokenKind kind);
  FileLoc here() const;
  void advance();  // moves past one character, keeping line and column up to date

  std::shared_ptr<const std::string> text_;
  std::shared_ptr<const std::string> filename_;
  size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
  bool has_peeked_ = false;
  Token peeked_;
};

/// How a token reads in a message: "'Foo'", "string \"abc\"", "end of file" (long texts shortened).
std::string describe(const Token& t);

/// `text` for a message: up to `max` bytes, then "... (N bytes)".
std::string shorten(const std::string& text, size_t max = 60);

/// The value of a Number token (std::from_chars, so no locale); a malformed or non-finite number is
/// an Error at the token.
double parse_number(const Token& t);

}  // namespace penumbra
