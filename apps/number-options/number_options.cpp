#include "number_options.h"

#include <fmt/core.h>

#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>

namespace penumbra::cli {

namespace {

// Long texts are cut in messages: the option's value is quoted, not echoed in full.
std::string quote_value(const std::string& text) {
  return text.size() <= 40 ? fmt::format("'{}'", text) : fmt::format("'{}...' ({} characters)", text.substr(0, 40), text.size());
}

// A finite number in decimal or scientific notation, above zero when `positive`.
CLI::Validator real_number(const std::string& words, bool positive, const std::string& name) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        double v = text.empty() ? 0.0 : std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || std::isnan(v))
          return fmt::format("expected {}, got {}", words, quote_value(text));
        if (!std::isfinite(v)) return fmt::format("expected {}, got {}, which is not finite", words, quote_value(text));
        if (positive && !(v > 0.0))
          return fmt::format("expected {}, got {}, which is not above zero", words, quote_value(text));
        return "";
      },
      "", name);
}

}  // namespace

CLI::Validator whole_number(int64_t lo, int64_t hi, const std::string& words) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* first = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
        const char* last = text.data() + text.size();
        int64_t v = 0;
        auto [ptr, ec] = std::from_chars(first, last, v);
        if (first == last || ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range))
          return fmt::format("expected {}, got {}", words, quote_value(text));
        if (ec == std::errc::result_out_of_range || v < lo || v > hi)
          return fmt::format("expected {}, got {}, which is out of that range", words, quote_value(text));
        return "";
      },
      "", "whole number");
}

CLI::Validator positive_whole_number() { return whole_number(1, INT_MAX, "a positive whole number (at most 2^31 - 1)"); }

CLI::Validator non_negative_whole_number() { return whole_number(0, INT_MAX, "a whole number from 0 to 2^31 - 1"); }

CLI::Validator seed_number() {
  return whole_number(0, UINT32_MAX, "a whole number from 0 to 2^32 - 1");
}

CLI::Validator positive_number(const std::string& unit) {
  return real_number(unit.empty() ? "a positive number" : "a positive number of " + unit, true, "positive number");
}

CLI::Validator finite_number(const std::string& unit) {
  return real_number(unit.empty() ? "a finite number" : "a finite number of " + unit, false, "number");
}

std::optional<int> parse_tool_options(CLI::App& app, int argc, char** argv, const std::string& prefix) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "{} {}\nRun with --help for usage.\n", prefix, e.what());
    return 2;
  }
  return std::nullopt;
}

}  // namespace penumbra::cli
