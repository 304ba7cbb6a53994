// alvio_map_info: what is in a map folder written by alvio (alvio run or the mapping
// nodelet): line count and length, voxel counts, extent, file sizes; optionally a
// top-view PNG (free space grey, occupied voxels shaded by height, lines red, the
// trajectory blue when trajectory.tum is there).
#include <octomap/OcTree.h>
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/map_files.h"
#include "alvio/mapping/occupancy_map.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  void add(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool valid() const { return (hi.array() >= lo.array()).all(); }
};

void writeTopView(const std::string& path, int size_px, const octomap::OcTree* tree,
                  const std::vector<MapLine>& lines, const Trajectory& trajectory, Box box) {
  if (!box.valid()) throw Error(path + ": the map is empty, nothing to draw");
  const double margin = 0.5;
  const double w = box.hi.x() - box.lo.x() + 2 * margin, h = box.hi.y() - box.lo.y() + 2 * margin;
  const double scale = size_px / std::max(w, h);
  cv::Mat img(static_cast<int>(std::ceil(h * scale)), static_cast<int>(std::ceil(w * scale)),
              CV_8UC3, cv::Scalar(255, 255, 255));
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x - box.lo.x() + margin) * scale)),
                     static_cast<int>(std::lround((box.hi.y() + margin - y) * scale)));
  };
  auto fill = [&](double x, double y, double half, const cv::Scalar& colour) {
    cv::rectangle(img, px(x - half, y + half), px(x + half, y - half), colour, cv::FILLED);
  };
  if (tree) {
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it)
      if (!tree->isNodeOccupied(*it)) fill(it.getX(), it.getY(), it.getSize() / 2, {225, 225, 225});
    // Occupied voxels, low ones first so the top of a column shows; darker = higher.
    std::vector<Eigen::Vector4d> occ;
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it)
      if (tree->isNodeOccupied(*it))
        occ.emplace_back(it.getX(), it.getY(), it.getZ(), it.getSize());
    std::sort(occ.begin(), occ.end(), [](const auto& a, const auto& b) { return a.z() < b.z(); });
    const double z0 = box.lo.z(), dz = std::max(1e-6, box.hi.z() - box.lo.z());
    for (const auto& v : occ) {
      const int g = static_cast<int>(170 - 150 * std::clamp((v.z() - z0) / dz, 0.0, 1.0));
      fill(v.x(), v.y(), v.w() / 2,
           {static_cast<double>(g), static_cast<double>(g), static_cast<double>(g)});
    }
  }
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    cv::line(img, px(trajectory[i - 1].p.x(), trajectory[i - 1].p.y()),
             px(trajectory[i].p.x(), trajectory[i].p.y()), {200, 80, 20}, 2, cv::LINE_AA);
  for (const MapLine& l : lines)
    cv::line(img, px(l.p0.x(), l.p0.y()), px(l.p1.x(), l.p1.y()), {30, 30, 220}, 2, cv::LINE_AA);
  // A 1 m scale bar.
  const cv::Point bar0(10, img.rows - 10), bar1(10 + static_cast<int>(scale), img.rows - 10);
  cv::line(img, bar0, bar1, {0, 0, 0}, 2);
  cv::putText(img, "1 m", bar0 + cv::Point(0, -6), cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0});
  if (!cv::imwrite(path, img)) throw Error(path + ": cannot write the image");
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio map-info DIR",
                 "Summarise a map folder (octomap.bt, lines.csv, map.3Dscene, trajectory.tum).");
  args.option("png", "also draw a top view into this PNG file");
  args.option("png-size", "longer side of the top view (px)", "1000");
  try {
    if (!args.parse(argc, argv)) return 0;
    if (args.positional().size() != 1) throw Error("alvio map-info: give one map folder (DIR)");
    const fs::path dir = args.positional().front();
    if (!fs::is_directory(dir)) throw Error(dir.string() + ": not a folder");

    Box box;
    std::cout << std::fixed << std::setprecision(3) << "map: " << dir.string() << "\n";
    std::vector<MapLine> lines;
    if (fs::exists(dir / kLinesCsvFileName)) {
      lines = readLinesCsv((dir / kLinesCsvFileName).string());
      double length = 0;
      long observations = 0;
      for (const MapLine& l : lines) {
        length += l.length();
        observations += l.observations;
        box.add(l.p0);
        box.add(l.p1);
      }
      std::cout << "lines: " << lines.size() << ", total length " << length << " m, "
                << observations << " observations\n";
      const std::string uncertainty = describeLineUncertainty(lines);
      if (!uncertainty.empty()) std::cout << uncertainty << "\n";
    } else {
      std::cout << "lines: (no " << kLinesCsvFileName << ")\n";
    }
    std::unique_ptr<octomap::OcTree> tree;
    if (fs::exists(dir / kOctomapFileName)) {
      tree = readOctomapBinary((dir / kOctomapFileName).string());
      const VoxelCounts c = countVoxels(*tree);
      std::cout << "voxels (" << tree->getResolution() << " m): " << c.occupied << " occupied, "
                << c.free << " free (" << c.leaf_nodes << " leaf nodes)\n";
      if (!c.empty()) {
        box.add(c.occupied_min);
        box.add(c.occupied_max);
      }
    } else {
      std::cout << "voxels: (no " << kOctomapFileName << ")\n";
    }
    Trajectory trajectory;
    if (fs::exists(dir / "trajectory.tum")) {
      try {
        trajectory = readTrajectory((dir / "trajectory.tum").string(), TrajectoryFormat::kTum);
      } catch (const Error& e) {
        std::cout << "trajectory: not used (" << e.what() << ")\n";
      }
      for (const StampedPose& p : trajectory) box.add(p.p);
      if (!trajectory.empty()) std::cout << "trajectory: " << trajectory.size() << " poses\n";
    }
    if (box.valid())
      std::cout << "extent: [" << box.lo.x() << ", " << box.lo.y() << ", " << box.lo.z() << "] .. ["
                << box.hi.x() << ", " << box.hi.y() << ", " << box.hi.z() << "] m ("
                << box.hi.x() - box.lo.x() << " x " << box.hi.y() - box.lo.y() << " x "
                << box.hi.z() - box.lo.z() << ")\n";
    else
      std::cout << "extent: (empty map)\n";
    std::cout << "files:";
    for (const char* f : {kOctomapFileName, kLinesPlyFileName, kLinesCsvFileName, kSceneFileName})
      if (fs::exists(dir / f))
        std::cout << " " << f << " " << std::setprecision(1) << fs::file_size(dir / f) / 1024.0
                  << " KiB";
    std::cout << "\n";
    if (args.isSet("png")) {
      writeTopView(args.get("png"), args.getInt("png-size"), tree.get(), lines, trajectory, box);
      std::cout << "top view: " << args.get("png") << "\n";
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio map-info: error: " << e.what() << "\n";
    return 2;
  }
}
