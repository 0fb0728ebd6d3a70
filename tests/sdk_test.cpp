// The plugin SDK's guarantees: the loader refuses plugins built with another compiler or for another
// SDK layout, naming the file and both identities, and plugins export nothing but their entry point.
// (scripts/test-sdk.sh covers the installed package and the out-of-tree example.)
#include "registry/registry.h"
#include "support/command.h"

#include <penumbra/version.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <set>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

std::string load_error(const std::string& name) {
  Registry r({PENUMBRA_TEST_PLUGIN_DIR});
  try {
    r.load(PluginKind::Integrator, name);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Names of the functions a shared library exports (nm -D lists defined dynamic symbols; T is text).
std::set<std::string> exported_functions(const std::string& path) {
  std::set<std::string> out;
  FILE* p = popen(("nm -D --defined-only '" + path + "' 2>/dev/null").c_str(), "r");
  if (!p) return out;
  char line[1024];
  while (fgets(line, sizeof line, p)) {
    char type = 0;
    char name[900] = {0};
    unsigned long long addr;
    if (sscanf(line, "%llx %c %899s", &addr, &type, name) == 3 && (type == 'T' || type == 'W' || type == 'i'))
      out.insert(name);
  }
  pclose(p);
  return out;
}

}  // namespace

TEST(Sdk, CompilerIdentityNamesCompilerAndStandardLibrary) {
  std::string id = PENUMBRA_COMPILER_ID;
  EXPECT_TRUE(id.rfind("gcc ", 0) == 0 || id.rfind("clang ", 0) == 0) << id;
  EXPECT_THAT(id, HasSubstr("libstdc++"));
}

TEST(Sdk, RefusesPluginBuiltWithAnotherCompiler) {
  std::string msg = load_error("foreigncc");
  EXPECT_THAT(msg, HasSubstr("penumbra-integrator-foreigncc.so was built with compiler 'othercc 99, otherlib'"));
  EXPECT_THAT(msg, HasSubstr(std::string("this runtime was built with '") + PENUMBRA_COMPILER_ID + "'"));
  EXPECT_THAT(msg, HasSubstr("both SDK version " + std::to_string(PENUMBRA_SDK_VERSION)));
}

TEST(Sdk, RefusesPluginWithTheOldLayoutOnItsVersionAlone) {
  // Version 1 had no compiler field: reading one would follow a garbage pointer.
  std::string msg = load_error("oldsdk");
  EXPECT_THAT(msg, HasSubstr("penumbra-integrator-oldsdk.so was built for Penumbra SDK version 1, but this "
                             "runtime has SDK version " + std::to_string(PENUMBRA_SDK_VERSION)));
}

TEST(Sdk, PluginsCommandReportsRefusedFilesAndFails) {
  test::CommandResult r = test::run_penumbra({"plugins", "--dir", PENUMBRA_TEST_PLUGIN_DIR});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("penumbra-integrator-foreigncc.so was built with compiler 'othercc 99, otherlib'"));
  EXPECT_THAT(r.err, HasSubstr("penumbra-integrator-oldsdk.so was built for Penumbra SDK version 1"));
}

TEST(Sdk, BuiltinPluginsExportOnlyTheirEntryPoint) {
  namespace fs = std::filesystem;
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(std::string(PENUMBRA_BINARY_DIR) + "/lib/penumbra/plugins")) {
    if (entry.is_symlink() || entry.path().extension() != ".so") continue;
    std::set<std::string> functions = exported_functions(entry.path().string());
    if (functions.empty()) GTEST_SKIP() << "nm is not available";
    EXPECT_EQ(functions, std::set<std::string>{"penumbra_plugin_info"}) << entry.path();
    ++checked;
  }
  EXPECT_GT(checked, 5);
}
