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

// With several runs, a study reports medians and quartiles of every metric, and a conclusion about a
// pair only when the bootstrap interval of their ratio excludes 1: a configuration that truncates
// paths at one bounce (biased: it misses the indirect light) is told apart; two identical ones are not.
TEST(Converge, RatiosWithIntervalsConcludeOnlyWhenTheIntervalExcludesOne) {
  std::string dir = test::temp_dir("converge-ratios");
  auto r = test::run_penumbra({"converge", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt",
                               "--configs", "path:independent,path/maxdepth=1:independent,path/rrdepth=3:independent",
                               "--make-reference", "2", "--time", "0.4", "--runs", "4", "--snapshots", "2",
                               "--res", "16x16", "--threads", "2", "-o", dir});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto summary = nlohmann::json::parse(test::read_file(dir + "/summary.json"));
  EXPECT_EQ(summary["runs"], 4);
  const auto& last = summary["configs"]["path:independent"]["points"].back();
  for (const char* m : {"relmse", "rmse", "mae", "relmse_clamped", "relse_median", "worst_share"}) {
    EXPECT_LE(last[std::string(m) + "_q25"].get<double>(), last[m].get<double>()) << m;
    EXPECT_LE(last[m].get<double>(), last[std::string(m) + "_q75"].get<double>()) << m;
  }
  bool truncated_seen = false, identical_seen = false;
  for (const auto& ratio : summary["ratios"]) {
    if (ratio["metric"] != "relmse") continue;
    EXPECT_LE(ratio["low"].get<double>(), ratio["ratio"].get<double>());
    EXPECT_LE(ratio["ratio"].get<double>(), ratio["high"].get<double>());
    if (ratio["a"] == "path:independent" && ratio["b"] == "path/maxdepth=1:independent") {
      truncated_seen = true;
      EXPECT_LT(ratio["high"].get<double>(), 1.0);
      EXPECT_EQ(ratio["conclusion"], "path:independent lower");
    }
    if (ratio["a"] == "path:independent" && ratio["b"] == "path/rrdepth=3:independent") {
      // The same seeds and settings: the runs differ only in the passes each finished in its time.
      identical_seen = true;
      EXPECT_LT(ratio["low"].get<double>(), 1.0);
      EXPECT_GT(ratio["high"].get<double>(), 1.0);
      EXPECT_EQ(ratio["conclusion"], "no conclusion: the interval contains 1");
    }
  }
  EXPECT_TRUE(truncated_seen);
  EXPECT_TRUE(identical_seen);
  EXPECT_THAT(r.err, HasSubstr("worst 0.1 % of pixels hold"));
  EXPECT_THAT(r.err, HasSubstr("path:independent / path/maxdepth=1:independent relmse at"));
}
