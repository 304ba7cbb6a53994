// The simulator's scene: geometry queries (ray casts, visibility, edges,
// clearance), the YAML scene files, and that the shipped scenes leave room for
// every trajectory that is flown through them.
#include <gtest/gtest.h>

#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/procedural_trajectories.h"
#include "alvio/sim/scene_file.h"
#include "test_support.h"

using namespace alvio;
using namespace alvio::sim;

namespace {

Scene unitBoxScene() {
  Scene scene;
  SceneMaterial m;
  m.name = "grey";
  scene.addMaterial(m);
  scene.addBox({0, 0, 0}, Eigen::Matrix3d::Identity(), {2, 2, 2}, 0, scene.addObject("box"));
  scene.finalize();
  return scene;
}

// Smallest clearance along a trajectory, with where and what.
std::string worstClearance(const Scene& scene, const Trajectory& t, double* worst) {
  *worst = 1e9;
  std::string where;
  for (std::size_t i = 0; i < t.size(); i += 4) {
    int object = -1;
    const double c = scene.clearance(t[i].p, &object);
    if (c < *worst) {
      *worst = c;
      where = "at t=" + std::to_string(t[i].t) + " p=(" + std::to_string(t[i].p.x()) + ", " +
              std::to_string(t[i].p.y()) + ", " + std::to_string(t[i].p.z()) + ") near '" +
              (object >= 0 ? scene.objectNames()[object] : "?") + "'";
    }
  }
  return where;
}

}  // namespace

TEST(SimScene, RayCastHitsTheNearFaceAtTheRightDistance) {
  const Scene scene = unitBoxScene();
  const auto hit = scene.intersect({-5, 0.3, 0.2}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4.0, 1e-9);
  EXPECT_NEAR(scene.quads()[hit->quad].normal().x(), -1.0, 1e-12);
  EXPECT_FALSE(scene.intersect({-5, 3, 0}, {1, 0, 0}));       // passes beside
  EXPECT_FALSE(scene.intersect({-5, 0, 0}, {1, 0, 0}, 3.9));  // stops short
  EXPECT_FALSE(scene.intersect({-5, 0, 0}, {-1, 0, 0}));      // looks away
}

TEST(SimScene, VisibilityOfPointsAndEdges) {
  const Scene scene = unitBoxScene();
  const Eigen::Vector3d eye(-5, -4, 3);
  EXPECT_FALSE(scene.isVisible({1.5, 0, 0}, eye));  // behind the box
  EXPECT_TRUE(scene.isVisible({-1.5, -3, 0}, eye));
  // Corners of the box: the one facing the eye is visible, the opposite one is not.
  EXPECT_TRUE(scene.isVisible({-1, -1, 1}, eye));
  EXPECT_FALSE(scene.isVisible({1, 1, -1}, eye));
  // Points along an edge facing the eye are visible (the surfaces touch them).
  EXPECT_TRUE(scene.isVisible({-1, -1, 0.3}, eye));
}

TEST(SimScene, BoxHasTwelveEdgesAndClearanceIsSigned) {
  const Scene scene = unitBoxScene();
  ASSERT_EQ(scene.edges().size(), 12u);
  ASSERT_EQ(scene.quads().size(), 6u);
  for (const SceneEdge& e : scene.edges()) EXPECT_NEAR((e.b - e.a).norm(), 2.0, 1e-12);
  EXPECT_NEAR(scene.clearance({3, 0, 0}), 2.0, 1e-12);
  EXPECT_NEAR(scene.clearance({0.5, 0, 0}), -0.5, 1e-12);
  // Every face is outward-facing: a ray from outside hits a face whose normal opposes it.
  for (const auto& d :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 1)}) {
    const auto hit = scene.intersect(-5 * d, d);
    ASSERT_TRUE(hit);
    EXPECT_LT(scene.quads()[hit->quad].normal().dot(d), -0.99);
  }
}

TEST(SimScene, EdgesAreCutWhereTheyRunInsideOtherSolids) {
  Scene scene;
  SceneMaterial m;
  m.name = "grey";
  scene.addMaterial(m);
  scene.addBox({0, 0, 0}, Eigen::Matrix3d::Identity(), {2, 2, 2}, 0, scene.addObject("a"));
  // A thin slab piercing the box: its 4 edges along x run through the box's inside, so each
  // leaves two pieces, x in [-3, -1] and [1, 3]; its 8 end edges stay whole.
  scene.addBox({0, 0, 0}, Eigen::Matrix3d::Identity(), {6, 0.2, 0.2}, 0, scene.addObject("b"));
  scene.finalize();
  EXPECT_EQ(scene.edges().size(), 12u + 8u + 8u);
  int pieces = 0;
  for (std::size_t i = 0; i < scene.edges().size(); ++i) {
    const SceneEdge& e = scene.edges()[i];
    EXPECT_EQ(e.id, static_cast<int>(i));
    if (std::abs(e.a.x() - e.b.x()) < 1e-9) continue;  // not along x
    if (std::abs(e.a.y()) > 0.5) continue;             // the box's own edges
    ++pieces;
    EXPECT_NEAR(std::abs(e.a.x() - e.b.x()), 2.0, 1e-6);
    EXPECT_NEAR(std::max(std::abs(e.a.x()), std::abs(e.b.x())), 3.0, 1e-6);
  }
  EXPECT_EQ(pieces, 8);
}

TEST(SimScene, ARailKeepsItsEdgesBetweenThePostsThatHoldIt) {
  // The machine hall's railings: the middle of a rail lies inside a post, which used to drop
  // the rail's long edges from the truth altogether.
  Scene scene;
  SceneMaterial m;
  m.name = "grey";
  scene.addMaterial(m);
  const int obj = scene.addObject("rail");
  for (double x : {-1.0, 0.0, 1.0})
    scene.addBox({x, 0, 0.5}, Eigen::Matrix3d::Identity(), {0.05, 0.05, 1.0}, 0, obj);
  scene.addBox({0, 0, 0.55}, Eigen::Matrix3d::Identity(), {2.0, 0.04, 0.04}, 0, obj);
  scene.finalize();
  double rail_length = 0;  // length of the rail's edges along x at z = 0.57
  for (const SceneEdge& e : scene.edges())
    if (std::abs(e.a.z() - 0.57) < 1e-9 && std::abs(e.b.z() - 0.57) < 1e-9 &&
        std::abs(e.a.y() - e.b.y()) < 1e-9 && std::abs(e.a.x() - e.b.x()) > 0.1)
      rail_length += std::abs(e.a.x() - e.b.x());
  // Two edges on top, each 2 m minus the inside of three posts (the end posts' outer halves
  // lie beyond the rail's ends): 2 x (2 - 0.025 - 0.05 - 0.025).
  EXPECT_NEAR(rail_length, 2 * 1.9, 1e-9);
}

TEST(SimSceneFile, ParsesObjectsAndReportsErrorsWithObjectAndKey) {
  const std::string ok = R"(
name: tiny
materials:
  grey: {pattern: noise, albedo: 0.5}
  glass: {pattern: plain, albedo: 0.9, emissive: 1.2}
objects:
  - {type: room, min: [0, 0, 0], max: [10, 8, 3], floor: grey, walls: grey, ceiling: grey}
  - {type: box, name: crate, center: [5, 4, 0.5], size: [1, 1, 1], yaw_deg: 30, material: grey,
     repeat: {count: 2, step: [2, 0, 0]}}
  - {type: frame, name: window, center: [0.05, 4, 2], size: [2, 1], normal: [1, 0, 0],
     material: grey, fill: glass}
  - {type: pipe, from: [1, 1, 2.5], to: [9, 1, 2.5], diameter: 0.1, material: grey}
  - {type: shelf, center: [5, 7, 0], size: [3, 0.6, 2], material: grey, goods: grey}
  - {type: tray, from: [1, 2, 2.7], to: [9, 2, 2.7], material: grey}
  - {type: quad, center: [9.99, 4, 1.5], size: [1, 0.7], normal: [-1, 0, 0], material: grey}
)";
  const SceneFile f = parseSceneText(ok, "tiny.yaml");
  EXPECT_EQ(f.scene.name, "tiny");
  // room 6 boxes, 2 crates, frame 4 bars + 1 pane, 1 pipe.
  EXPECT_GE(f.scene.solids().size(), 6u + 2u + 4u + 1u);
  EXPECT_NEAR(f.scene.clearance({5, 4, 0.5}), -0.5, 1e-9);  // inside the first crate
  EXPECT_LT(f.scene.clearance({7, 4, 0.5}), 0.0);           // the repeated crate

  auto expectError = [](const std::string& text, const std::string& needle) {
    try {
      parseSceneText(text, "bad.yaml");
      ADD_FAILURE() << "no error for: " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectError(
      "materials: {g: {pattern: noise}}\nobjects:\n  - {type: box, name: b1, center: "
      "[0, 0, 0], material: g}\n",
      "bad.yaml: objects[0] ('b1'): key 'size' is missing");
  expectError(
      "materials: {g: {pattern: noise}}\nobjects:\n  - {type: box, center: [0, 0], "
      "size: [1, 1, 1], material: g}\n",
      "key 'center' must be a list of 3 numbers");
  expectError(
      "materials: {g: {pattern: noise}}\nobjects:\n  - {type: box, center: [0, 0, 0], "
      "size: [1, 1, 1], material: nope}\n",
      "undefined material 'nope'");
  expectError("materials: {g: {pattern: marble}}\nobjects: []\n",
              "materials.g: unknown texture pattern 'marble'");
  expectError("materials: {g: {pattern: noise}}\nobjects:\n  - {type: sphere}\n",
              "key 'type' is unknown");
}

TEST(SimSceneFile, ShippedScenesLoad) {
  for (const std::string name : {"machine_hall", "corridor", "plain_room"}) {
    const SceneFile f = loadSceneFile(name);
    EXPECT_GT(f.scene.quads().size(), 20u) << name;
    EXPECT_GT(f.scene.edges().size(), 40u) << name;
  }
}

TEST(SimSceneFile, BuiltInPathsStayClearOfTheirScenes) {
  const Config config = Config::load(Config::defaultPath());
  for (const std::string name : {"machine_hall", "corridor", "plain_room"}) {
    const SceneFile f = loadSceneFile(name);
    for (const std::string path : {"figure8", "corridor"}) {
      if (name == "corridor" && path == "figure8") continue;  // a figure eight needs a hall
      ProceduralPathOptions o;
      o.duration_s = 120;
      o.rate_hz = 20;
      o.T_b_c = config.camera.T_b_c;
      o.figure_eight = f.figure_eight;
      o.corridor = f.corridor;
      double worst;
      const std::string where = worstClearance(f.scene, makeProceduralTrajectory(path, o), &worst);
      EXPECT_GT(worst, 0.3) << path << " in " << name << ": " << where;
    }
  }
}

TEST(SimSceneFile, MachineHallLeavesRoomForEveryEurocMhFlight) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const SceneFile f = loadSceneFile("machine_hall");
  for (const std::string seq :
       {"MH_01_easy", "MH_02_easy", "MH_03_medium", "MH_04_difficult", "MH_05_difficult"}) {
    const Trajectory t =
        readTrajectory(data + "/euroc_groundtruth/xygxgn_VINS-Fusion/output/" + seq + ".txt");
    double worst;
    const std::string where = worstClearance(f.scene, t, &worst);
    EXPECT_GT(worst, 0.25) << seq << ": " << where;
    // The walls are a realistic few metres away, not hundreds.
    const Eigen::AlignedBox3d box = f.scene.bounds();
    EXPECT_LT(box.sizes().maxCoeff(), 40.0);
    std::cout << seq << ": smallest clearance " << worst << " m " << where << "\n";
  }
}

TEST(SimEdgeProjection, VisibleEdgesAndOcclusion) {
  // A camera at the origin looking along +z (camera frame = world frame), a 1 m box
  // 5 m ahead, and a 1 m box 10 m ahead that the near one partly hides.
  Scene scene;
  SceneMaterial m;
  m.name = "grey";
  scene.addMaterial(m);
  scene.addBox({0, 0, 5}, Eigen::Matrix3d::Identity(), {1, 1, 1}, 0, scene.addObject("near"));
  scene.addBox({0.9, 0, 10}, Eigen::Matrix3d::Identity(), {1, 1, 1}, 0, scene.addObject("far"));
  scene.finalize();
  const Config config = Config::load(Config::defaultPath());
  const auto camera = CameraModel::create(config.camera);
  const auto visible =
      projectVisibleEdges(scene, *camera, Eigen::Isometry3d::Identity(), EdgeProjectionOptions{});
  int near_edges = 0;
  bool far_right = false, far_top = false;
  for (const VisibleEdge& v : visible) {
    const SceneEdge& e = scene.edges()[v.edge_id];
    const std::string& object = scene.objectNames()[e.object];
    // The end points project as the camera model says.
    Eigen::Vector2d pa;
    ASSERT_TRUE(camera->project(v.a_w, &pa));
    EXPECT_LT((pa - v.a_px).norm(), 1e-9);
    const bool front = std::abs(e.a.z() - e.b.z()) < 1e-9;  // in a face facing the camera
    if (object == "near") {
      // Only the front face (z = 4.5) shows; its edges are seen whole.
      ++near_edges;
      EXPECT_NEAR(e.a.z(), 4.5, 1e-9);
      EXPECT_GT(v.visible_fraction, 0.95);
      continue;
    }
    // The far box (x 0.4..1.4, front face z = 9.5) is partly behind the near one.
    ASSERT_TRUE(front) << "a receding edge of the far box cannot be seen";
    const bool vertical = std::abs(e.a.x() - e.b.x()) < 1e-9;
    if (vertical) {
      EXPECT_NEAR(e.a.x(), 1.4, 1e-9) << "the far box's left edge is hidden by the near box";
      EXPECT_GT(v.visible_fraction, 0.95);
      far_right = true;
    } else if (e.a.y() > 0) {
      // Hidden where x / 9.5 < 0.5 / 4.5, i.e. x < 1.056: about 1/3 of it shows.
      EXPECT_NEAR(v.visible_fraction, (1.4 - 0.5 / 4.5 * 9.5) / 1.0, 0.05);
      far_top = true;
    }
  }
  EXPECT_EQ(near_edges, 4);
  EXPECT_TRUE(far_right);
  EXPECT_TRUE(far_top);
}
