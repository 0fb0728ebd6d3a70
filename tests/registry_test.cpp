// The plugin registry: lookup by name and alias, refusal of plugins built for another SDK, and the
// guarantee that a render opens only the plugins its scene names.
#include "registry/registry.h"
#include "support/command.h"

#include <penumbra/integrator.h>
#include <penumbra/sampler.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

std::vector<std::string> builtin_dirs() { return {std::string(PENUMBRA_BINARY_DIR) + "/lib/penumbra/plugins"}; }

}  // namespace

TEST(Registry, FindsBuiltinPluginsByNameAndAlias) {
  Registry r(builtin_dirs());
  EXPECT_STREQ(r.load(PluginKind::Integrator, "path").info->name, "path");
  EXPECT_STREQ(r.load(PluginKind::Sampler, "random").info->name, "independent");
  EXPECT_EQ(r.loaded(), (std::vector<std::string>{"integrator/path", "sampler/independent"}));
}

TEST(Registry, UnknownPluginListsAvailableOnes) {
  Registry r(builtin_dirs());
  try {
    r.load(PluginKind::Integrator, "pathh");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown integrator 'pathh'; available: "));
    EXPECT_THAT(e.what(), HasSubstr("path"));
  }
}

TEST(Registry, RefusesPluginBuiltForAnotherSdkVersion) {
  Registry r({PENUMBRA_TEST_PLUGIN_DIR});
  try {
    r.load(PluginKind::Integrator, "future");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("penumbra-integrator-future.so was built for Penumbra SDK version 999"));
    EXPECT_THAT(e.what(), HasSubstr("this runtime has SDK version " + std::to_string(PENUMBRA_SDK_VERSION)));
  }
}

TEST(Registry, RefusesLibraryWithoutEntryPoint) {
  Registry r({PENUMBRA_TEST_PLUGIN_DIR});
  try {
    r.load(PluginKind::Sampler, "notaplugin");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("is not a Penumbra plugin"));
  }
}

TEST(Registry, SearchesPluginPathAfterBuiltinFolder) {
  Registry r(builtin_dirs());
  auto dirs = Registry::default_search_dirs();
  ASSERT_FALSE(dirs.empty());
  // The test binary lives in build/bin next to penumbra: the first folder is the built-in one.
  EXPECT_EQ(std::filesystem::weakly_canonical(dirs[0]), std::filesystem::weakly_canonical(builtin_dirs()[0]));
}

TEST(Registry, CreateValidatesParametersWithSuggestion) {
  Registry r(builtin_dirs());
  ParamSet params;
  Param p{"integer", "maxdeph", {}, {5.0}, {}, {}};
  params.add(p);
  try {
    r.create<Integrator>(PluginKind::Integrator, "path", params, CreateContext{params}, {});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "unknown parameter 'maxdeph' for integrator 'path'; did you mean 'maxdepth'?");
  }
}

TEST(Registry, PluginsCommandListsParametersWithoutRendering) {
  test::CommandResult r = test::run_penumbra({"plugins"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("integrator 'path'"));
  EXPECT_THAT(r.out, HasSubstr("maxdepth"));
  EXPECT_THAT(r.out, HasSubstr("[default = 5]"));
  EXPECT_THAT(r.out, HasSubstr("sampler 'independent' (alias 'random')"));
  EXPECT_THAT(r.out, HasSubstr("bsdf 'diffuse'"));
  EXPECT_THAT(r.out, HasSubstr("light 'diffuse'"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("rendered")));
}

TEST(Registry, PluginPathEnvironmentVariableIsSearched) {
  test::CommandResult r = test::run_penumbra({"plugins"}, std::string("PENUMBRA_PLUGIN_PATH=") + PENUMBRA_TEST_PLUGIN_DIR);
  EXPECT_THAT(r.out, HasSubstr(PENUMBRA_TEST_PLUGIN_DIR));
  // The mismatched plugin is found there and refused, so the command reports it and fails.
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("SDK version 999"));
}
