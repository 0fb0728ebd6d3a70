// Errors that reach the user. Scene problems carry the file, line and column they come from; the
// command-line program prints them as "file:line:col: error: message" and exits with status 1.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

namespace penumbra {

/// A position in a scene file (1-based line and column). An empty filename means "no location".
struct FileLoc {
  std::shared_ptr<const std::string> filename;
  std::shared_ptr<const std::string> source;  // the file's text, to quote the line in messages
  int line = 0;
  int column = 0;
  std::string str() const;  // "file:line:col" or "" when unknown
};

/// Any error the user can fix: bad scene, bad parameter, missing file, unusable plugin.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(const FileLoc& loc, const std::string& message)
      : std::runtime_error(message), loc_(loc) {}
  const FileLoc& loc() const { return loc_; }
  /// "file:line:col: error: message" (or "error: message" without a location), followed by the
  /// offending source line with a caret under the column when the text is known.
  std::string formatted() const;

 private:
  FileLoc loc_;
};

/// Prints a one-line warning to stderr, located when `loc` is known.
void warning(const FileLoc& loc, const std::string& message);

}  // namespace penumbra
