#include "alvio/mapping/map_files.h"

#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <octomap/OcTree.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/io/trajectory_io.h"

namespace alvio {

std::string linesToPly(const std::vector<MapLine>& lines) {
  std::ostringstream os;
  os << "ply\n"
     << "format ascii 1.0\n"
     << "comment alvio line map: one vertex per line endpoint, one edge per line\n"
     << "comment vertex x y z: endpoint in the world frame (m)\n"
     << "comment edge vertex1 vertex2: 0-based indices of the line's two vertices\n"
     << "comment edge id: map line ID (as in lines.csv)\n"
     << "comment edge observations: image observations summed over merged landmarks\n"
     << "comment edge landmarks: number of landmark IDs merged into the line\n"
     << "comment edge midpoint_std_m: 1-sigma midpoint uncertainty across the line of its "
        "best-placed landmark (m), -1 when unknown\n"
     << "element vertex " << 2 * lines.size() << "\n"
     << "property float x\nproperty float y\nproperty float z\n"
     << "element edge " << lines.size() << "\n"
     << "property int vertex1\nproperty int vertex2\n"
     << "property int id\nproperty int observations\nproperty int landmarks\n"
     << "property float midpoint_std_m\n"
     << "end_header\n";
  os << std::setprecision(9);
  for (const MapLine& l : lines) {
    os << l.p0.x() << " " << l.p0.y() << " " << l.p0.z() << "\n";
    os << l.p1.x() << " " << l.p1.y() << " " << l.p1.z() << "\n";
  }
  for (std::size_t i = 0; i < lines.size(); ++i)
    os << 2 * i << " " << 2 * i + 1 << " " << lines[i].id << " " << lines[i].observations << " "
       << lines[i].landmarks << " " << lines[i].midpoint_std_m << "\n";
  return os.str();
}

std::string linesToCsv(const std::vector<MapLine>& lines) {
  std::ostringstream os;
  os << "id,x0,y0,z0,x1,y1,z1,observations,landmarks,midpoint_std_m\n"
     << std::fixed << std::setprecision(6);
  for (const MapLine& l : lines)
    os << l.id << "," << l.p0.x() << "," << l.p0.y() << "," << l.p0.z() << "," << l.p1.x() << ","
       << l.p1.y() << "," << l.p1.z() << "," << l.observations << "," << l.landmarks << ","
       << l.midpoint_std_m << "\n";
  return os.str();
}

std::vector<MapLine> readLinesCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::string row;
  std::vector<MapLine> out;
  int line_no = 0;
  while (std::getline(in, row)) {
    ++line_no;
    if (row.empty() || row[0] == '#' || row.rfind("id,", 0) == 0) continue;
    std::istringstream is(row);
    MapLine l;
    char c[8];
    is >> l.id >> c[0] >> l.p0.x() >> c[1] >> l.p0.y() >> c[2] >> l.p0.z() >> c[3] >> l.p1.x() >>
        c[4] >> l.p1.y() >> c[5] >> l.p1.z() >> c[6] >> l.observations >> c[7] >> l.landmarks;
    const auto bad = [&] {
      return Error(path + ":" + std::to_string(line_no) +
                   ": expected id,x0,y0,z0,x1,y1,z1,observations,landmarks[,midpoint_std_m]");
    };
    if (!is || std::string(c, 8) != ",,,,,,,,") throw bad();
    // The tenth column is optional: files written before it was added have nine.
    char sep = 0;
    if (is >> sep && (sep != ',' || !(is >> l.midpoint_std_m))) throw bad();
    out.push_back(l);
  }
  return out;
}

void writeOctomapBinary(const std::string& path, const octomap::OcTree& tree) {
  std::ostringstream os(std::ios::binary);
  if (!tree.writeBinaryConst(os)) throw Error(path + ": OctoMap could not serialise the tree");
  writeFileAtomically(path, os.str());
}

std::unique_ptr<octomap::OcTree> readOctomapBinary(const std::string& path) {
  if (!std::filesystem::exists(path)) throw Error(path + ": no such file");
  auto tree = std::make_unique<octomap::OcTree>(0.1);
  if (!tree->readBinary(path)) throw Error(path + ": not a readable OctoMap binary (.bt) file");
  return tree;
}

void writeScene(const std::string& path, const SceneContent& content) {
  using namespace mrpt::opengl;
  COpenGLScene scene;

  auto trajectory = CSetOfLines::Create();
  trajectory->setName(kSceneTrajectoryName);
  trajectory->setColor(0.1f, 0.3f, 0.9f);
  trajectory->setLineWidth(2.0f);
  for (std::size_t i = 1; i < content.trajectory.size(); ++i) {
    const Eigen::Vector3d& a = content.trajectory[i - 1].p;
    const Eigen::Vector3d& b = content.trajectory[i].p;
    trajectory->appendLine(a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  }
  scene.insert(trajectory);

  auto points = CPointCloud::Create();
  points->setName(kScenePointsName);
  points->setColor(0.1f, 0.1f, 0.1f);
  points->setPointSize(3.0f);
  for (const Eigen::Vector3d& p : content.points) points->insertPoint(p.x(), p.y(), p.z());
  scene.insert(points);

  auto lines = CSetOfLines::Create();
  lines->setName(kSceneLinesName);
  lines->setColor(0.9f, 0.1f, 0.1f);
  lines->setLineWidth(2.0f);
  for (const MapLine& l : content.lines)
    lines->appendLine(l.p0.x(), l.p0.y(), l.p0.z(), l.p1.x(), l.p1.y(), l.p1.z());
  scene.insert(lines);

  auto voxels = CPointCloud::Create();
  voxels->setName(kSceneVoxelsName);
  voxels->setColor(0.5f, 0.5f, 0.5f, 0.6f);
  voxels->setPointSize(2.0f);
  for (const Eigen::Vector3d& p : content.voxel_centres) voxels->insertPoint(p.x(), p.y(), p.z());
  scene.insert(voxels);

  // COpenGLScene::saveToFile writes a gzip stream to the given name; rename it in place.
  const std::string tmp = path + ".tmp";
  if (!scene.saveToFile(tmp)) {
    std::remove(tmp.c_str());
    throw Error(path + ": MRPT could not write the scene");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw Error(path + ": cannot rename from " + tmp + ": " + ec.message());
}

}  // namespace alvio
