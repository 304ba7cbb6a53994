// The simulator-truth helpers of the evaluations: distances to scene surfaces, the edge CSV
// read back, the scene named by sim_info.yaml, and ground truth interpolated at image times.
#include <gtest/gtest.h>

#include <fstream>

#include "alvio/common/error.h"
#include "alvio/eval/trajectory_interpolation.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/procedural_texture.h"
#include "alvio/sim/sequence_generator.h"
#include "alvio/sim/sequence_scene.h"
#include "alvio/sim/surface_distance.h"
#include "test_support.h"

using namespace alvio;
using Eigen::Vector3d;

TEST(SimTruth, SurfaceDistanceToRectangles) {
  EXPECT_NEAR(sim::pointRectangleDistance(Vector3d(0.5, 0.5, 2), Vector3d::Zero(),
                                          Vector3d::UnitX(), Vector3d::UnitY()),
              2.0, 1e-12);
  EXPECT_NEAR(sim::pointRectangleDistance(Vector3d(4, 0.5, 0), Vector3d::Zero(), Vector3d::UnitX(),
                                          Vector3d::UnitY()),
              3.0, 1e-12);
  sim::Scene scene;
  const int object = scene.addObject("box");
  scene.addMaterial({"grey", {}});
  scene.addBox(Vector3d::Zero(), Eigen::Matrix3d::Identity(), Vector3d(2, 2, 2), 0, object);
  scene.finalize();
  const sim::SurfaceDistance distance(scene);
  EXPECT_NEAR(distance(Vector3d(0, 0, 3)), 2.0, 1e-12);             // above the top face
  EXPECT_NEAR(distance(Vector3d(0.2, 0, 0)), 0.8, 1e-12);           // inside: nearest face at x = 1
  EXPECT_NEAR(distance(Vector3d(2, 2, 0)), std::sqrt(2.0), 1e-12);  // off a vertical edge
}

TEST(SimTruth, SceneOfASequenceIsCheckedAgainstItsEdges) {
  const std::string dir = test::scratchDir();
  const sim::SceneFile hall = sim::loadSceneFile("plain_room");
  sim::writeSceneEdgesCsv(dir + "/scene_edges.csv", hall.scene);
  const std::vector<sim::SceneEdge> back = sim::readSceneEdgesCsv(dir + "/scene_edges.csv");
  ASSERT_EQ(back.size(), hall.scene.edges().size());
  EXPECT_EQ(back[3].id, hall.scene.edges()[3].id);
  EXPECT_NEAR((back[3].b - hall.scene.edges()[3].b).norm(), 0.0, 1e-6);
  std::ofstream(dir + "/sim_info.yaml") << "# Written by the alvio simulator.\n"
                                        << "#   scene: plain_room.yaml 0123456789abcdef\n"
                                        << "#   imu: real 7f320d242e19fa62\n"
                                        << "#   start: 0 still: -1 seed: 1 texture: poor\n"
                                        << "frames: 3\n";
  EXPECT_EQ(sim::sceneNameFromSimInfo(dir + "/sim_info.yaml"), "plain_room.yaml");
  EXPECT_EQ(sim::textureDensityFromSimInfo(dir + "/sim_info.yaml"),
            sim::parseTextureDensity("poor"));
  EXPECT_EQ(sim::imuModeFromSimInfo(dir + "/sim_info.yaml"), "real");
  // A real IMU: groundtruth.tum is not the rendered trajectory, the truth tools refuse it.
  EXPECT_THROW(sim::requireRenderedGroundTruth(dir), Error);
  EXPECT_EQ(sim::loadSequenceScene(dir).scene.edges().size(), back.size());
  // The sequence was rendered in another scene: refuse to score against this one.
  EXPECT_THROW(sim::loadSequenceScene(dir, "corridor"), Error);
  std::ofstream(dir + "/sim_info.yaml") << "#   scene: plain_room.yaml 0123456789abcdef\n"
                                        << "#   imu: synthetic\n";
  EXPECT_NO_THROW(sim::requireRenderedGroundTruth(dir));
}

TEST(SimTruth, StaleEdgesOfASequenceAreRewrittenFromItsScene) {
  const std::string dir = test::scratchDir();
  const sim::SceneFile room = sim::loadSceneFile("plain_room");
  // Edges as an older simulator may have written them (here: none at all).
  std::ofstream(dir + "/scene_edges.csv") << "#id,ax,ay,az,bx,by,bz,object\n";
  std::ofstream(dir + "/sim_info.yaml")
      << "#   scene: plain_room.yaml " << sim::fileHash(sim::resolveScenePath("plain_room.yaml"))
      << "\n";
  EXPECT_THROW(sim::loadSequenceScene(dir), Error);
  EXPECT_TRUE(sim::refreshSceneEdges(dir));
  EXPECT_EQ(sim::loadSequenceScene(dir).scene.edges().size(), room.scene.edges().size());
  EXPECT_FALSE(sim::refreshSceneEdges(dir));  // now current: left alone
  // Rendered from another version of the scene file: the images may differ, refuse.
  std::ofstream(dir + "/sim_info.yaml") << "#   scene: plain_room.yaml 0123456789abcdef\n";
  try {
    sim::refreshSceneEdges(dir);
    ADD_FAILURE() << "a scene file edited since rendering was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("0123456789abcdef"), std::string::npos) << e.what();
  }
}

TEST(SimTruth, PoseInterpolation) {
  Trajectory t(2);
  t[0].t = 1.0;
  t[1].t = 1.01;
  t[1].p = Vector3d(1, 0, 0);
  t[1].q = Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Vector3d::UnitZ()));
  const auto mid = interpolatePose(t, 1.0025);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->p.x(), 0.25, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(mid->q).angle(), 0.05, 1e-9);
  const Eigen::Isometry3d T_w_b = mid->T_w_b();  // what the truth tools project with
  EXPECT_NEAR((T_w_b * Vector3d::Zero() - mid->p).norm(), 0.0, 1e-12);
  EXPECT_NEAR((T_w_b.linear() * Vector3d::UnitX() - mid->q * Vector3d::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_TRUE(interpolatePose(t, 1.01));
  EXPECT_FALSE(interpolatePose(t, 0.99));
  EXPECT_FALSE(interpolatePose(t, 1.02));
  EXPECT_FALSE(interpolatePose(t, 1.005, 0.005));  // a hole in the ground truth
}
