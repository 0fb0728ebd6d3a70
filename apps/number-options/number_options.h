// Validators for the numbers given on the command line, linked as the library target
// penumbra-number-options by the penumbra program, penumbra-make-sky and the benchmark programs.
// CLI11's own range validators print their bounds as numbers (PositiveNumber's upper bound is
// DBL_MAX, 309 digits) and let NaN through; these check the whole text, refuse NaN and infinity,
// and state the accepted range in words:
// "--spp: expected a positive whole number, got '0'".
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace penumbra::cli {

/// A whole number (decimal, optional sign) in [lo, hi]; `words` names the range in the message,
/// e.g. "a positive whole number" or "a whole number of threads from 1 to 1024".
CLI::Validator whole_number(int64_t lo, int64_t hi, const std::string& words);

/// The common cases.
CLI::Validator positive_whole_number();      // 1 .. 2^31 - 1, said so in words
CLI::Validator non_negative_whole_number();  // 0 .. 2^31 - 1
CLI::Validator seed_number();                // 0 .. 2^32 - 1

/// A finite number greater than zero (decimal or scientific notation); `unit` ends the message,
/// e.g. "seconds" gives "expected a positive number of seconds".
CLI::Validator positive_number(const std::string& unit = "");
/// Any finite number (decimal or scientific notation), e.g. an angle in degrees.
CLI::Validator finite_number(const std::string& unit = "");

/// How the programs beside penumbra (penumbra-make-sky, the benchmark programs) read their command
/// line: parses `app`; on --help prints the usage and returns 0, on a bad option prints
/// "`prefix` MESSAGE" and a pointer to --help on stderr and returns 2; otherwise returns nothing and
/// the program goes on.
std::optional<int> parse_tool_options(CLI::App& app, int argc, char** argv, const std::string& prefix);

}  // namespace penumbra::cli
