// `penumbra converge` end to end on a tiny Cornell box: it makes a reference, takes log-spaced
// snapshots of every run without stopping a pass, and writes CSV and JSON whose errors fall with time.
#include "support/command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

using namespace penumbra;
using ::testing::HasSubstr;

TEST(Converge, WritesSnapshotsWhoseErrorFallsWithTime) {
  std::string dir = test::temp_dir("converge");
  auto r = test::run_penumbra({"converge", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt",
                               "--configs", "path:independent,path:sobol", "--make-reference", "2", "--time", "0.8",
                               "--runs", "2", "--snapshots", "4", "--res", "24x24", "-o", dir});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string csv = test::read_file(dir + "/results.csv");
  EXPECT_THAT(csv, HasSubstr("config,run,snapshot,seconds,spp,rmse,relmse,mae"));
  auto summary = nlohmann::json::parse(test::read_file(dir + "/summary.json"));
  EXPECT_EQ(summary["relmse_epsilon"], 0.01);
  EXPECT_TRUE(summary["reference_variance_subtracted"].get<bool>());
  for (const char* name : {"path:independent", "path:sobol"}) {
    const auto& points = summary["configs"][name]["points"];
    ASSERT_GE(points.size(), 3u) << name;
    // Snapshots are taken after whole passes: spp grows and the error at the end is below the first.
    EXPECT_GT(points.back()["spp"].get<double>(), points.front()["spp"].get<double>());
    EXPECT_LT(points.back()["relmse"].get<double>(), points.front()["relmse"].get<double>()) << name;
    EXPECT_GT(summary["configs"][name]["efficiency"].get<double>(), 0.0);
  }
  EXPECT_TRUE(summary["time_to_reach"]["seconds"].contains("path:sobol"));
}

TEST(Converge, BadConfigurationIsAnError) {
  auto r = test::run_penumbra({"converge", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt",
                               "--configs", ":sobol", "--make-reference", "1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--configs: ':sobol' names no integrator"));
  r = test::run_penumbra({"converge", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt",
                          "--configs", "path"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--reference REF.exr or --make-reference SECONDS"));
}
