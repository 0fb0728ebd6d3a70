#include "support/command.h"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace penumbra::test {

static std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string temp_dir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("penumbra-test-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::string write_file(const std::string& dir, const std::string& name, const std::string& text) {
  fs::path p = fs::path(dir) / name;
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
  return p.string();
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

CommandResult run_program(const std::string& program, const std::vector<std::string>& args, const std::string& env) {
  static int counter = 0;
  std::string dir = temp_dir("cmd" + std::to_string(counter++));
  std::string cmd = env + (env.empty() ? "" : " ") + quote(program);
  for (const auto& a : args) cmd += " " + quote(a);
  cmd += " >" + quote(dir + "/out") + " 2>" + quote(dir + "/err") + " </dev/null";
  int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(dir + "/out");
  r.err = read_file(dir + "/err");
  return r;
}

}  // namespace

CommandResult run_penumbra(const std::vector<std::string>& args, const std::string& env) {
  return run_program(PENUMBRA_BINARY, args, env);
}

CommandResult run_tool(const std::string& name, const std::vector<std::string>& args) {
  return run_program((fs::path(PENUMBRA_BINARY).parent_path() / name).string(), args, "");
}

}  // namespace penumbra::test
