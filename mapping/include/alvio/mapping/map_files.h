#pragma once
// The map files, each written atomically (a temporary file in the same folder,
// then a rename, so a crash never leaves half a map):
//
//   octomap.bt    the occupancy tree in OctoMap's binary format (octovis, bt2vrml, ...)
//   lines.ply     ASCII PLY: one vertex per line endpoint and one edge per line
//                   vertex: x y z            world frame, metres (float)
//                   edge:   vertex1 vertex2  0-based indices of its two vertices (int)
//                           id               map line ID, as in lines.csv (int)
//                           observations     image observations summed over merged landmarks
//                           landmarks        landmark IDs merged into the line (int)
//                           midpoint_std_m   1-sigma midpoint uncertainty across the line of
//                                            its best-placed landmark, m; -1 unknown (float)
//   lines.csv     header `id,x0,y0,z0,x1,y1,z1,observations,landmarks,midpoint_std_m`, one
//                 line per row, endpoints in the world frame (m); files without the last
//                 column (written before it existed) still read
//   map.3Dscene   an MRPT COpenGLScene (gzip-compressed, SceneViewer3D) with the objects
//                 named "trajectory" (CSetOfLines, a strip through the body positions),
//                 "points" (CPointCloud of point landmarks), "lines" (CSetOfLines, one
//                 segment per map line) and "occupied_voxels" (CPointCloud of voxel centres)

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/mapping/line_map.h"

namespace octomap {
class OcTree;
}

namespace alvio {

inline constexpr const char* kOctomapFileName = "octomap.bt";
inline constexpr const char* kLinesPlyFileName = "lines.ply";
inline constexpr const char* kLinesCsvFileName = "lines.csv";
inline constexpr const char* kSceneFileName = "map.3Dscene";

inline constexpr const char* kSceneTrajectoryName = "trajectory";
inline constexpr const char* kScenePointsName = "points";
inline constexpr const char* kSceneLinesName = "lines";
inline constexpr const char* kSceneVoxelsName = "occupied_voxels";

/// The lines as ASCII PLY text (vertices + edges, columns documented in header comments).
std::string linesToPly(const std::vector<MapLine>& lines);
/// The lines as CSV text.
std::string linesToCsv(const std::vector<MapLine>& lines);
/// Read lines.csv; throws alvio::Error naming the file and line of a malformed row.
std::vector<MapLine> readLinesCsv(const std::string& path);

/// Write the tree in OctoMap's binary format (.bt), atomically. Throws alvio::Error.
void writeOctomapBinary(const std::string& path, const octomap::OcTree& tree);
/// Read a .bt file; throws alvio::Error when it cannot be read.
std::unique_ptr<octomap::OcTree> readOctomapBinary(const std::string& path);

/// What goes into map.3Dscene.
struct SceneContent {
  Trajectory trajectory;                       ///< body poses T_w_b
  std::vector<Eigen::Vector3d> points;         ///< point landmarks
  std::vector<MapLine> lines;                  ///< map lines
  std::vector<Eigen::Vector3d> voxel_centres;  ///< occupied voxels
};
/// Write an MRPT scene (.3Dscene), atomically; needs no display. Throws alvio::Error.
void writeScene(const std::string& path, const SceneContent& content);

}  // namespace alvio
