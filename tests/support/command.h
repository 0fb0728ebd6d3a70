// Runs the penumbra program as a user would and captures what it says.
#pragma once

#include <string>
#include <vector>

namespace penumbra::test {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

/// Runs build/bin/penumbra with `args` (each shell-quoted) and optional environment assignments.
CommandResult run_penumbra(const std::vector<std::string>& args, const std::string& env = "");
/// Runs another program of penumbra's folder (e.g. "penumbra-make-sky") the same way.
CommandResult run_tool(const std::string& name, const std::vector<std::string>& args);

/// A fresh temporary folder for one test.
std::string temp_dir(const std::string& name);
/// Writes `text` to `dir/name` and returns the path.
std::string write_file(const std::string& dir, const std::string& name, const std::string& text);
std::string read_file(const std::string& path);

}  // namespace penumbra::test
