// Configuration overrides (the nodelets' `config` ROS parameters): an overlay
// replaces single keys and keeps the rest, and bad overrides are reported with
// the key, through the same loaders as the file.
#include <gtest/gtest.h>

#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_overlay.h"
#include "alvio/config/yaml_reader.h"
#include "test_support.h"

using namespace alvio;

TEST(YamlOverlay, ReplacesLeavesAndKeepsTheRest) {
  const std::string base = "%YAML:1.0\na: 1\nb:\n  c: 2\n  d: [1, 2]\n";
  const std::string merged = overlayYaml(base, "base.yaml", "b:\n  c: 5\n  e: x\nf: true\n", "ros");
  const YamlReader yaml = YamlReader::fromString(merged, "merged");
  EXPECT_EQ(yaml.getInt("a"), 1);
  EXPECT_EQ(yaml.getInt("b.c"), 5);
  EXPECT_EQ(yaml.getDoubles("b.d").size(), 2u);
  EXPECT_EQ(yaml.getString("b.e"), "x");
  EXPECT_TRUE(yaml.getBool("f"));
}

TEST(YamlOverlay, LeafKeysAreDottedPaths) {
  const auto keys = yamlLeafKeys(
      "estimator:\n  window_size: 8\n  line_triangulation:\n"
      "    min_plane_angle_deg: 2\npoints:\n  max_features: 100\n");
  EXPECT_EQ(keys, (std::vector<std::string>{"estimator.window_size",
                                            "estimator.line_triangulation.min_plane_angle_deg",
                                            "points.max_features"}));
}

TEST(YamlOverlay, TheConfigLoaderValidatesOverriddenKeys) {
  const std::string path = test::sourcePath("config/euroc.yaml");
  const std::string file = readTextFile(path);
  const Config ok = Config::load(YamlReader::fromString(
      overlayYaml(file, path, "estimator:\n  window_size: 7\n", "ROS"), "merged"));
  EXPECT_EQ(ok.estimator.window_size, 7);
  EXPECT_EQ(ok.points.max_features, 150) << "untouched keys keep the file's value";
  try {
    Config::load(YamlReader::fromString(
        overlayYaml(file, path, "estimator:\n  use_lines: maybe\n", "ROS"), "merged"));
    FAIL() << "a non-boolean use_lines must be rejected";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("estimator.use_lines"), std::string::npos) << e.what();
  }
}

TEST(YamlOverlay, AGroupOverASingleValueIsAnError) {
  EXPECT_THROW(overlayYaml("a: 1\n", "base", "a:\n  b: 2\n", "ROS"), Error);
  EXPECT_THROW(overlayYaml("a: 1\n", "base", "[1, 2]\n", "ROS"), Error);
  EXPECT_THROW(readTextFile("/nonexistent/alvio.yaml"), Error);
}

TEST(YamlOverlay, AssignmentsBecomeNestedOverlays) {
  EXPECT_EQ(assignmentToYaml("estimator.selection.points=true"),
            "estimator:\n  selection:\n    points: true\n");
  const std::string merged =
      overlayYaml("estimator:\n  window_size: 10\n  max_iterations: 8\n", "base.yaml",
                  assignmentToYaml("estimator.window_size=6"), "--set");
  const YamlReader yaml = YamlReader::fromString(merged, "merged");
  EXPECT_EQ(yaml.getInt("estimator.window_size"), 6);
  EXPECT_EQ(yaml.getInt("estimator.max_iterations"), 8);
  EXPECT_THROW(assignmentToYaml("estimator.window_size"), Error);
  EXPECT_THROW(assignmentToYaml("=3"), Error);
  EXPECT_THROW(assignmentToYaml("estimator..window_size=3"), Error);
}

TEST(YamlOverlay, AssignmentListsSplitOnlyBetweenAssignments) {
  using List = std::vector<std::string>;
  EXPECT_EQ(splitAssignments("a=1"), List({"a=1"}));
  EXPECT_EQ(splitAssignments("a=1,b.c=true"), List({"a=1", "b.c=true"}));
  // A sequence value keeps its commas, so `--set camera.resolution=[640,480]` works.
  EXPECT_EQ(splitAssignments("camera.resolution=[640,480],a=2"),
            List({"camera.resolution=[640,480]", "a=2"}));
  EXPECT_EQ(splitAssignments("m={x: 1, y: [2, 3]},s='a,b',t=\"c,d\""),
            List({"m={x: 1, y: [2, 3]}", "s='a,b'", "t=\"c,d\""}));
  EXPECT_THROW(splitAssignments("a=[1,2"), Error);
  EXPECT_THROW(splitAssignments("a=1]"), Error);
  EXPECT_THROW(splitAssignments("a='x"), Error);
  const YamlReader yaml = YamlReader::fromString(
      assignmentToYaml(splitAssignments("camera.resolution=[640,480]").front()), "--set");
  EXPECT_EQ(yaml.getDoubles("camera.resolution", 2), std::vector<double>({640, 480}));
}
