// alvio_map_truth: a map written by `alvio run` against the simulator's true scene. The
// estimated trajectory (trajectory.tum) is aligned to groundtruth.tum, by default in position
// and yaw only: a VIO's world frame is levelled by gravity, and a full SE(3) fit may tilt it to
// absorb position drift (0.9 degrees on one sim_MH_01 run whose attitudes were within 0.03 of
// level), which swings lines 10 m away by 15 cm. That alignment brings the map lines (lines.csv)
// and the occupied OctoMap voxels (octomap.bt) into the true world, where they are compared with
// the scene's edges and surfaces: line angle and midpoint distance to the nearest true edge, line
// map precision / recall, fraction of voxels near a surface, and the map's size. The line figures
// are given twice: against the geometry's edges alone, and against those plus the straight albedo
// edges of the surfaces' textures (brick joints, seams, stripes: sim/texture_edges.h), which a line
// map rightly holds too.
#include <octomap/OcTree.h>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/eval/trajectory_evaluation.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/map_files.h"
#include "alvio/mapping/map_truth_evaluation.h"
#include "alvio/mapping/occupancy_map.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/sequence_scene.h"
#include "alvio/sim/surface_distance.h"
#include "alvio/sim/texture_edges.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {
std::uintmax_t sizeOf(const fs::path& p) {
  return fs::exists(p) ? fs::file_size(p) : 0;
}
}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_map_truth",
                 "A run's map (lines.csv, octomap.bt) against the simulator's true scene.\n"
                 "Usage: alvio_map_truth [options] RUN_DIR SEQUENCE_DIR");
  args.option("scene", "scene file or name (default: the one sim_info.yaml names)", "");
  args.option("line-distance", "line map tolerance: distance to a true edge (m)", "0.10");
  args.option("line-angle", "line map tolerance: angle to a true edge (deg)", "3");
  args.option("voxel-tolerance", "voxel centre to a true surface (m); default 2 voxels", "");
  args.flag("no-texture-edges", "judge lines against the geometry's edges only (faster)");
  args.option("align", "trajectory alignment that places the map: posyaw | se3", "posyaw");
  args.option("json", "write every figure to this JSON file");
  args.option("per-line",
              "write each map line's error, endpoints (true world) and midpoint uncertainty "
              "to this CSV file");
  try {
    if (!args.parse(argc, argv)) return 0;
    if (args.positional().size() != 2) throw Error("give RUN_DIR and SEQUENCE_DIR");
    const fs::path run = args.positional()[0], seq = args.positional()[1];

    sim::requireRenderedGroundTruth(seq.string());  // the map is aligned through its poses
    // Alignment estimate -> truth from the trajectories.
    const Trajectory est = readTrajectory((run / "trajectory.tum").string());
    const Trajectory gt = readTrajectory((seq / "groundtruth.tum").string());
    EvaluationOptions eo;
    const std::string align = args.get("align");
    if (align != "posyaw" && align != "se3")
      throw Error("--align must be posyaw or se3, not '" + align + "'");
    eo.alignment = parseAlignmentMode(align);
    const EvaluationResult traj = evaluateTrajectory(est, gt, eo);

    const sim::SceneFile scene = sim::loadSequenceScene(seq.string(), args.get("scene"));
    std::vector<Segment3> edges;
    for (const sim::SceneEdge& e : scene.scene.edges()) edges.push_back({e.a, e.b});
    const sim::SurfaceDistance surfaces(scene.scene);
    const SurfaceDistanceFn surface_distance = [&](const Eigen::Vector3d& p) {
      return surfaces(p);
    };

    const std::vector<MapLine> map_lines = readLinesCsv((run / kLinesCsvFileName).string());
    std::vector<Segment3> lines;
    for (const MapLine& l : map_lines) lines.push_back(l.segment());
    const std::unique_ptr<octomap::OcTree> tree =
        readOctomapBinary((run / kOctomapFileName).string());

    MapTruthOptions options;
    options.line_distance_tol_m = args.getDouble("line-distance");
    options.line_angle_tol_deg = args.getDouble("line-angle");
    options.voxel_tolerance_m = args.isSet("voxel-tolerance") ? args.getDouble("voxel-tolerance")
                                                              : 2 * tree->getResolution();
    const MapTruthEvaluation m = evaluateMapAgainstTruth(lines, tree.get(), traj.alignment, edges,
                                                         surface_distance, options);
    // The same lines against the geometry's and the textures' edges together.
    std::vector<Segment3> all_edges = edges;
    std::size_t texture_edges = 0;
    if (!args.isSet("no-texture-edges")) {
      sim::AppearanceOptions ao;
      ao.texture_density = sim::textureDensityFromSimInfo((seq / "sim_info.yaml").string());
      ao.occlusion_rays = 0;  // light maps are not needed: no shadow or occlusion rays
      ao.shadows = false;
      for (const sim::SceneEdge& e :
           sim::sceneTextureEdges(scene.scene, sim::SceneAppearance(scene.scene, ao))) {
        all_edges.push_back({e.a, e.b});
        ++texture_edges;
      }
    }
    const MapTruthEvaluation mt =
        texture_edges > 0 ? evaluateMapAgainstTruth(lines, nullptr, traj.alignment, all_edges,
                                                    surface_distance, options)
                          : MapTruthEvaluation{};
    const VoxelCounts voxels = countVoxels(*tree);

    const nlohmann::json report = {
        {"run", run.string()},
        {"sequence", seq.string()},
        {"alignment",
         {{"mode", align},
          {"matched_poses", traj.matched},
          {"ate_rmse_m", traj.ate_translation_m.rmse},
          {"ate_median_m", traj.ate_translation_m.median}}},
        {"lines",
         {{"count", m.line_errors.lines},
          {"median_angle_deg", m.line_errors.median_angle_deg},
          {"p90_angle_deg", m.line_errors.p90_angle_deg},
          {"median_midpoint_distance_m", m.line_errors.median_midpoint_distance_m},
          {"p90_midpoint_distance_m", m.line_errors.p90_midpoint_distance_m},
          {"tolerance",
           {{"distance_m", options.line_distance_tol_m},
            {"angle_deg", options.line_angle_tol_deg}}},
          {"precision", m.line_map.precision},
          {"on_surface_length_fraction", m.line_on_surface_fraction},
          {"recall", m.line_map.recall},
          {"map_length_m", m.line_map.map_length_m},
          {"true_edges", m.line_map.true_edges},
          {"true_length_m", m.line_map.true_length_m},
          {"with_texture_edges",
           {{"texture_edges", texture_edges},
            {"precision", mt.line_map.precision},
            {"median_angle_deg", mt.line_errors.median_angle_deg},
            {"median_midpoint_distance_m", mt.line_errors.median_midpoint_distance_m},
            {"p90_midpoint_distance_m", mt.line_errors.p90_midpoint_distance_m}}}}},
        {"octomap",
         {{"resolution_m", tree->getResolution()},
          {"occupied_voxels", m.occupancy.occupied_voxels},
          {"free_voxels", voxels.free},
          {"tolerance_m", options.voxel_tolerance_m},
          {"fraction_near_surface", m.occupancy.fraction},
          {"mean_surface_distance_m", m.occupancy.mean_distance_m}}},
        {"memory",
         {{"octree_bytes", tree->memoryUsage()},
          {"line_count", map_lines.size()},
          {"octomap_bt_bytes", sizeOf(run / kOctomapFileName)},
          {"lines_csv_bytes", sizeOf(run / kLinesCsvFileName)},
          {"lines_ply_bytes", sizeOf(run / kLinesPlyFileName)}}}};

    std::cout << std::fixed << std::setprecision(3)
              << "alignment: " << (align == "se3" ? "SE(3)" : "position + yaw") << " over "
              << traj.matched << " poses, ATE RMSE " << traj.ate_translation_m.rmse << " m\n"
              << "lines: " << m.line_errors.lines << "  angle to nearest true edge median "
              << m.line_errors.median_angle_deg << " deg (p90 " << m.line_errors.p90_angle_deg
              << ")  midpoint distance median " << m.line_errors.median_midpoint_distance_m
              << " m (p90 " << m.line_errors.p90_midpoint_distance_m << ")\n"
              << "line map (" << options.line_distance_tol_m << " m, " << options.line_angle_tol_deg
              << " deg): precision " << 100 * m.line_map.precision << " %  recall "
              << 100 * m.line_map.recall << " % of " << m.line_map.true_length_m
              << " m of true edges; " << 100 * m.line_on_surface_fraction
              << " % of the map line length lies on a true surface\n";
    if (texture_edges > 0)
      std::cout << "with the " << texture_edges << " texture edges as truth too: precision "
                << 100 * mt.line_map.precision << " %  angle median "
                << mt.line_errors.median_angle_deg << " deg  midpoint distance median "
                << mt.line_errors.median_midpoint_distance_m << " m (p90 "
                << mt.line_errors.p90_midpoint_distance_m << ")\n";
    std::cout << "octomap: " << m.occupancy.occupied_voxels << " occupied voxels, "
              << 100 * m.occupancy.fraction << " % within " << options.voxel_tolerance_m
              << " m of a surface (mean distance " << m.occupancy.mean_distance_m << " m)\n"
              << "memory: octree " << tree->memoryUsage() << " B, " << map_lines.size()
              << " lines; files octomap.bt " << sizeOf(run / kOctomapFileName) << " B, lines.csv "
              << sizeOf(run / kLinesCsvFileName) << " B, lines.ply "
              << sizeOf(run / kLinesPlyFileName) << " B\n";
    if (args.isSet("json")) writeFileAtomically(args.get("json"), report.dump(2) + "\n");
    if (args.isSet("per-line")) {
      std::ostringstream os;
      os << "id,length_m,observations,landmarks,edge,angle_deg,midpoint_distance_m,"
            "surface_distance_m,midpoint_surface_distance_m,precision,texture_midpoint_distance_m,"
            "precision_with_texture_edges,x0,y0,z0,x1,y1,z1,midpoint_std_m\n";
      for (const MapLine& l : map_lines) {
        const Segment3 s{traj.alignment.apply(l.p0), traj.alignment.apply(l.p1)};
        const LineError e = lineErrorToNearestEdge(s, edges);
        const LineMapEvaluation one = evaluateLineMap({s}, edges, options.line_distance_tol_m,
                                                      options.line_angle_tol_deg * kDegToRad);
        const LineError et = lineErrorToNearestEdge(s, all_edges);
        const LineMapEvaluation one_t = evaluateLineMap({s}, all_edges, options.line_distance_tol_m,
                                                        options.line_angle_tol_deg * kDegToRad);
        os << l.id << "," << s.length() << "," << l.observations << "," << l.landmarks << ","
           << e.edge << "," << e.angle_deg << "," << e.midpoint_distance_m << ","
           << lineSurfaceDistance(s, surface_distance) << "," << surfaces(0.5 * (s.p0 + s.p1))
           << "," << one.precision << "," << et.midpoint_distance_m << "," << one_t.precision;
        for (const Eigen::Vector3d& p : {s.p0, s.p1})
          os << "," << p.x() << "," << p.y() << "," << p.z();
        os << "," << l.midpoint_std_m << "\n";
      }
      writeFileAtomically(args.get("per-line"), os.str());
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_map_truth: error: " << e.what() << "\n";
    return 2;
  }
}
