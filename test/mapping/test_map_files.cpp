// Map files: every file written by MapBuilder::save is read back with its own library
// (OctoMap, MRPT, a PLY reader written here, the CSV reader) and the counts checked;
// octomap-tools' bt2vrml reads the .bt.
#include <gtest/gtest.h>

#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <octomap/OcTree.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/map_builder.h"
#include "alvio/mapping/map_files.h"
#include "alvio/mapping/synthetic_room.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

// A minimal ASCII PLY reader: element counts, property names and rows per element.
struct Ply {
  std::vector<std::string> comments;
  std::vector<std::string> element_order;
  std::map<std::string, std::vector<std::string>> properties;
  std::map<std::string, std::vector<std::vector<double>>> rows;
};

Ply readPly(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  Ply ply;
  std::map<std::string, std::size_t> counts;
  std::getline(in, line);
  if (line != "ply") throw Error(path + ": no 'ply' magic");
  std::getline(in, line);
  if (line != "format ascii 1.0") throw Error(path + ": not ASCII PLY 1.0");
  std::string current;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream is(line);
    std::string word;
    is >> word;
    if (word == "comment") {
      ply.comments.push_back(line.substr(8));
    } else if (word == "element") {
      std::size_t n = 0;
      is >> current >> n;
      counts[current] = n;
      ply.element_order.push_back(current);
    } else if (word == "property") {
      std::string type, name;
      is >> type >> name;
      ply.properties[current].push_back(name);
    } else {
      throw Error(path + ": unexpected header line '" + line + "'");
    }
  }
  for (const std::string& e : ply.element_order)
    for (std::size_t i = 0; i < counts[e]; ++i) {
      if (!std::getline(in, line)) throw Error(path + ": file ends inside element " + e);
      std::istringstream is(line);
      std::vector<double> row(ply.properties[e].size());
      for (double& v : row) is >> v;
      if (!is) throw Error(path + ": short row in element " + e);
      ply.rows[e].push_back(row);
    }
  if (std::getline(in, line) && !line.empty()) throw Error(path + ": data after the last element");
  return ply;
}

std::size_t occupiedLeaves(const octomap::OcTree& tree) {
  std::size_t n = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
    if (tree.isNodeOccupied(*it)) ++n;
  return n;
}

// A small map of the synthetic room: one lap.
MapBuilder& smallMap() {
  static MapBuilder* builder = [] {
    SyntheticRoomOptions ro;
    ro.laps = 1;
    ro.keyframes_per_lap = 40;
    const SyntheticRoom room = makeSyntheticRoom(ro);
    auto* b = new MapBuilder();
    for (std::size_t k = 0; k < room.keyframes.size(); ++k) {
      b->addKeyframe(room.keyframes[k]);
      b->addTrajectoryPose(room.trajectory[k]);
    }
    return b;
  }();
  return *builder;
}

}  // namespace

TEST(MapFiles, EveryFileReloadsWithItsOwnLibrary) {
  const std::string dir = test::scratchDir();
  const MapBuilder& map = smallMap();
  const MapFilePaths paths = map.save(dir);
  const std::vector<MapLine> kept = map.lineMap().filteredLines();
  ASSERT_GT(kept.size(), 10u);
  ASSERT_GT(map.points().size(), 100u);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_NE(entry.path().extension(), ".tmp") << "left behind: " << entry.path();

  // OctoMap.
  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary(paths.octomap));
  EXPECT_DOUBLE_EQ(tree.getResolution(), map.occupancyMap().options().resolution);
  const VoxelCounts original = map.occupancyMap().counts(), reloaded = countVoxels(tree);
  EXPECT_GT(reloaded.occupied, 1000u);
  EXPECT_EQ(reloaded.occupied, original.occupied);
  EXPECT_EQ(reloaded.free, original.free);

  // MRPT scene.
  mrpt::opengl::COpenGLScene scene;
  ASSERT_TRUE(scene.loadFromFile(paths.scene));
  auto lines =
      std::dynamic_pointer_cast<mrpt::opengl::CSetOfLines>(scene.getByName(kSceneLinesName));
  auto trajectory =
      std::dynamic_pointer_cast<mrpt::opengl::CSetOfLines>(scene.getByName(kSceneTrajectoryName));
  auto points =
      std::dynamic_pointer_cast<mrpt::opengl::CPointCloud>(scene.getByName(kScenePointsName));
  auto voxels =
      std::dynamic_pointer_cast<mrpt::opengl::CPointCloud>(scene.getByName(kSceneVoxelsName));
  ASSERT_TRUE(lines && trajectory && points && voxels);
  EXPECT_EQ(lines->size(), kept.size());
  EXPECT_EQ(trajectory->size(), map.trajectory().size() - 1);
  EXPECT_EQ(points->size(), map.points().size());
  EXPECT_EQ(voxels->size(), original.occupied);
  const auto first = *lines->begin();
  EXPECT_NEAR(first.point1.x, kept.front().p0.x(), 1e-6);
  EXPECT_NEAR(first.point2.z, kept.front().p1.z(), 1e-6);

  // PLY.
  const Ply ply = readPly(paths.lines_ply);
  ASSERT_EQ(ply.element_order, (std::vector<std::string>{"vertex", "edge"}));
  EXPECT_EQ(ply.properties.at("vertex"), (std::vector<std::string>{"x", "y", "z"}));
  EXPECT_EQ(ply.properties.at("edge"),
            (std::vector<std::string>{"vertex1", "vertex2", "id", "observations", "landmarks",
                                      "midpoint_std_m"}));
  ASSERT_EQ(ply.rows.at("vertex").size(), 2 * kept.size());
  ASSERT_EQ(ply.rows.at("edge").size(), kept.size());
  EXPECT_GE(ply.comments.size(), 4u);  // the columns are documented
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const auto& e = ply.rows.at("edge")[i];
    const auto& v0 = ply.rows.at("vertex").at(static_cast<std::size_t>(e[0]));
    const auto& v1 = ply.rows.at("vertex").at(static_cast<std::size_t>(e[1]));
    EXPECT_NEAR(v0[0], kept[i].p0.x(), 1e-4);
    EXPECT_NEAR(v1[2], kept[i].p1.z(), 1e-4);
    EXPECT_EQ(static_cast<int>(e[2]), kept[i].id);
    EXPECT_EQ(static_cast<int>(e[3]), kept[i].observations);
    EXPECT_NEAR(e[5], kept[i].midpoint_std_m, 1e-6);
  }

  // CSV.
  const std::vector<MapLine> csv = readLinesCsv(paths.lines_csv);
  ASSERT_EQ(csv.size(), kept.size());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(csv[i].id, kept[i].id);
    EXPECT_EQ(csv[i].observations, kept[i].observations);
    EXPECT_LT((csv[i].p0 - kept[i].p0).norm(), 1e-5);
    EXPECT_LT((csv[i].p1 - kept[i].p1).norm(), 1e-5);
    EXPECT_NEAR(csv[i].midpoint_std_m, kept[i].midpoint_std_m, 1e-6);
  }
}

TEST(MapFiles, LinesCsvCarriesTheMidpointUncertaintyAndReadsOlderFiles) {
  const std::string dir = test::scratchDir();
  std::vector<MapLine> lines(2);
  lines[0].id = 4;
  lines[0].p1 = Eigen::Vector3d(1, 0, 0);
  lines[0].midpoint_std_m = 0.0123;
  lines[1].id = 9;
  lines[1].p1 = Eigen::Vector3d(0, 2, 0);  // unknown: -1
  writeFileAtomically(dir + "/lines.csv", linesToCsv(lines));
  const std::vector<MapLine> back = readLinesCsv(dir + "/lines.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_NEAR(back[0].midpoint_std_m, 0.0123, 1e-9);
  EXPECT_NEAR(back[1].midpoint_std_m, -1.0, 1e-9);
  // Nine columns, as written before the uncertainty was added: read, uncertainty unknown.
  std::ofstream(dir + "/old.csv") << "id,x0,y0,z0,x1,y1,z1,observations,landmarks\n"
                                  << "3,0,0,0,1,0,0,7,2\n";
  const std::vector<MapLine> old = readLinesCsv(dir + "/old.csv");
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].landmarks, 2);
  EXPECT_LT(old[0].midpoint_std_m, 0);
  std::ofstream(dir + "/junk.csv") << "3,0,0,0,1,0,0,7,2;0.5\n";
  EXPECT_THROW(readLinesCsv(dir + "/junk.csv"), Error);
}

TEST(MapFiles, OctomapToolsReadTheBinaryTree) {
  // octomap-tools (Debian) has no octree2pointcloud; bt2vrml reads a .bt and writes every
  // occupied leaf as a VRML box.
  ASSERT_EQ(std::system("command -v bt2vrml >/dev/null 2>&1"), 0)
      << "bt2vrml not found: install the Debian package octomap-tools (./alvio does)";
  const std::string dir = test::scratchDir();
  const MapFilePaths paths = smallMap().save(dir);
  const std::string cmd = "cd '" + dir + "' && bt2vrml octomap.bt > bt2vrml.log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "bt2vrml failed, see " << dir << "/bt2vrml.log";
  std::ifstream wrl(dir + "/octomap.bt.wrl");
  ASSERT_TRUE(wrl.good());
  std::string line;
  std::size_t boxes = 0;
  while (std::getline(wrl, line))
    if (line.rfind("Transform { translation", 0) == 0) ++boxes;
  EXPECT_EQ(boxes, occupiedLeaves(smallMap().occupancyMap().tree()));
  EXPECT_GT(boxes, 1000u);
}

TEST(MapFiles, ReadersRejectBadFiles) {
  const std::string dir = test::scratchDir();
  std::ofstream(dir + "/bad.csv") << "id,x0,y0,z0,x1,y1,z1,observations,landmarks\n1,2,3\n";
  try {
    readLinesCsv(dir + "/bad.csv");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2"), std::string::npos) << e.what();
  }
  std::ofstream(dir + "/bad.bt") << "not an octree\n";
  EXPECT_THROW(readOctomapBinary(dir + "/bad.bt"), Error);
  EXPECT_THROW(readOctomapBinary(dir + "/missing.bt"), Error);
  // Unwritable destination: an error, and no file appears.
  EXPECT_THROW(writeScene(dir + "/no/such/dir/map.3Dscene", SceneContent()), Error);
}
