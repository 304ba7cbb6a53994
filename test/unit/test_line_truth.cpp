// Line trackers against true scene edges: the association of a 2D segment with the projected
// edge it lies on, the per-track scoring, and the two end to end on images of a box drawn
// from its own geometry (so the truth is exact) while the camera moves.
#include <gtest/gtest.h>

#include <cmath>
#include <iterator>

#include <opencv2/imgproc.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/eval/line_track_truth.h"
#include "alvio/lines/line_tracker.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/scene.h"

using namespace alvio;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

ProjectedEdge edge(int id, Vector2d a, Vector2d b) {
  ProjectedEdge e;
  e.edge_id = id;
  e.a = a;
  e.b = b;
  return e;
}

LineObservation obs(int id, Vector2d a, Vector2d b) {
  LineObservation o;
  o.id = id;
  o.start_px = a;
  o.end_px = b;
  return o;
}

}  // namespace

TEST(LineTruthAssociation, ToleranceAngleOverlapAndNearest) {
  const ProjectedEdges edges = {edge(7, {100, 100}, {300, 100}),    // horizontal
                                edge(8, {100, 102}, {300, 102}),    // 2 px below it
                                edge(9, {400, 100}, {600, 100}),    // collinear, further right
                                edge(10, {100, 100}, {100, 300})};  // vertical
  // On edge 7, reversed direction (edges are undirected), 0.5 px off: 7 closest, 8 also fits.
  EdgeAssociation a = associateWithEdge(LineSegment({250, 100.5}, {150, 100.5}), edges);
  EXPECT_EQ(a.edge_id, 7);
  EXPECT_NEAR(a.endpoint_distance_px, 0.5, 1e-9);
  EXPECT_EQ(a.compatible, (std::vector<int>{7, 8}));
  // 5 px off every horizontal edge: nothing.
  EXPECT_EQ(associateWithEdge(LineSegment({150, 95}, {250, 95}), edges).edge_id, -1);
  // 5 degrees off around the middle of edge 7: endpoints within 3 px? no (4.4 px), and the
  // angle fails too; at 2 degrees on a short segment it passes.
  const double t5 = std::tan(5 * M_PI / 180) * 25, t2 = std::tan(2 * M_PI / 180) * 25;
  EXPECT_EQ(associateWithEdge(LineSegment({175, 100 - t5}, {225, 100 + t5}), edges).edge_id, -1);
  EXPECT_EQ(associateWithEdge(LineSegment({175, 100 - t2}, {225, 100 + t2}), edges).edge_id, 7);
  // Between edges 7 and 9 on their common image line: mostly beyond 7's visible part and not
  // on 9's either.
  EXPECT_EQ(associateWithEdge(LineSegment({280, 100}, {390, 100}), edges).edge_id, -1);
  EXPECT_EQ(associateWithEdge(LineSegment({420, 100}, {520, 100}), edges).edge_id, 9);
  EXPECT_EQ(associateWithEdge(LineSegment({100.4, 150}, {100.4, 250}), edges).edge_id, 10);
}

TEST(LineTrackTruth, CountsEdgeSwitchesAndTrackLengths) {
  const ProjectedEdges truth = {edge(1, {0, 0}, {200, 0}), edge(2, {0, 50}, {200, 50}),
                                edge(3, {0, 100}, {200, 100})};
  LineTrackTruth score;
  for (int k = 0; k < 5; ++k) {
    LineFrame f;
    f.lines.push_back(obs(10, {20, 0.3}, {180, 0.3}));  // always edge 1
    if (k < 4)                                          // edge 2 three times, then edge 3
      f.lines.push_back(obs(11, {20, k < 3 ? 50.0 : 100.0}, {180, k < 3 ? 50.0 : 100.0}));
    if (k == 2) f.lines.push_back(obs(12, {20, 75}, {180, 75}));  // texture line, on no edge
    f.stats.merged = 1;
    f.stats.clipped = k == 4;
    f.stats.track_ms = 2;
    score.addFrame(f, truth);
  }
  const LineTrackTruthSummary s = score.summarise();
  EXPECT_EQ(s.frames, 5u);
  EXPECT_EQ(s.tracks, 3u);
  EXPECT_EQ(s.observations, 10u);
  EXPECT_NEAR(s.mean_track_length_frames, (5 + 4 + 1) / 3.0, 1e-9);
  EXPECT_NEAR(s.associated_fraction, 9 / 10.0, 1e-9);
  EXPECT_EQ(s.evaluated_tracks, 2u);
  EXPECT_NEAR(s.correct_fraction, 8 / 9.0, 1e-9);
  EXPECT_NEAR(s.strict_correct_fraction, 8 / 9.0, 1e-9);
  EXPECT_NEAR(s.single_edge_track_fraction, 0.5, 1e-9);
  EXPECT_EQ(s.type3_merged, 5u);
  EXPECT_EQ(s.type4_clipped, 1u);
  EXPECT_NEAR(s.mean_ms, 2.0, 1e-9);
}

TEST(LineTrackTruth, EndpointErrorBinnedBySegmentLength) {
  const ProjectedEdges truth = {edge(1, {0, 0}, {400, 0})};
  LineTrackTruth score;
  LineFrame f;
  f.lines.push_back(obs(1, {0, 0.5}, {50, 1.5}));    // 50 px: endpoints 0.5 and 1.5 px off
  f.lines.push_back(obs(2, {0, -0.2}, {250, 0.2}));  // 250 px: 0.2 and 0.2
  f.lines.push_back(obs(3, {0, 0.1}, {350, -0.3}));  // 350 px, the open bin: 0.1 and 0.3
  f.lines.push_back(obs(4, {0, 20}, {100, 20}));     // on no edge: not counted
  score.addFrame(f, truth);
  const LineTrackTruthSummary s = score.summarise();
  const std::size_t bins = std::size(LineTrackTruth::kEndpointBinEdgesPx);
  ASSERT_EQ(s.endpoint_error_by_length.size(), bins);
  const EndpointErrorBin& shortest = s.endpoint_error_by_length.front();
  EXPECT_EQ(shortest.min_length_px, 0);
  EXPECT_EQ(shortest.max_length_px, 60);
  EXPECT_EQ(shortest.endpoints, 2u);
  // Distances to the true line, not to the segment's own: 50 px with a 1 px rise is a tilt.
  EXPECT_NEAR(shortest.rms_px, std::sqrt((0.25 + 2.25) / 2), 1e-9);
  EXPECT_EQ(s.endpoint_error_by_length[1].endpoints, 0u);
  EXPECT_EQ(s.endpoint_error_by_length[4].endpoints, 2u);  // [200, 300)
  EXPECT_NEAR(s.endpoint_error_by_length[4].rms_px, 0.2, 1e-9);
  const EndpointErrorBin& longest = s.endpoint_error_by_length.back();
  EXPECT_EQ(longest.min_length_px, 300);
  EXPECT_TRUE(std::isinf(longest.max_length_px));
  EXPECT_NEAR(longest.rms_px, std::sqrt((0.01 + 0.09) / 2), 1e-9);
}

namespace {

// A box on a dark background, drawn face by face from its own quads with a flat shade each:
// the image edges are exactly the projected scene edges.
struct BoxWorld {
  sim::Scene scene;
  CameraOptions camera;
  std::unique_ptr<CameraModel> model;

  BoxWorld() {
    const int object = scene.addObject("box");
    scene.addMaterial({"grey", {}});
    scene.addBox(Vector3d(4, 0, 0.5), Eigen::AngleAxisd(0.5, Vector3d::UnitZ()).toRotationMatrix(),
                 Vector3d(1.2, 1.0, 1.0), 0, object);
    scene.finalize();
    camera.distortion_model = "none";
    camera.distortion_coefficients.clear();
    model = CameraModel::create(camera);
  }

  // Camera at `centre` looking at (4, 0, 0.5), image y pointing down.
  static Eigen::Isometry3d lookAt(const Vector3d& centre) {
    const Vector3d z = (Vector3d(4, 0, 0.5) - centre).normalized();
    const Vector3d x = z.cross(Vector3d::UnitZ()).normalized();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() << x, z.cross(x), z;
    T.translation() = centre;
    return T;
  }

  cv::Mat1b render(const Eigen::Isometry3d& T_w_c) const {
    cv::Mat1b image(camera.height, camera.width, uchar(30));
    const Eigen::Isometry3d T_c_w = T_w_c.inverse();
    const Vector3d centre = T_w_c.translation();
    int shade = 0;
    for (const sim::SceneQuad& q : scene.quads()) {
      ++shade;
      if (q.normal().dot(centre - q.origin) <= 0) continue;  // back face of the convex box
      std::vector<cv::Point> poly;
      for (int i = 0; i < 4; ++i) {
        Vector2d px;
        model->project(T_c_w * q.corner(i), &px);
        poly.emplace_back(cvRound(px.x() * 16), cvRound(px.y() * 16));
      }
      cv::fillConvexPoly(image, poly, cv::Scalar(90 + 25 * shade), cv::LINE_AA, 4);
    }
    return image;
  }

  ProjectedEdges truth(const Eigen::Isometry3d& T_w_c) const {
    ProjectedEdges out;
    for (const sim::VisibleEdge& v : sim::projectVisibleEdges(scene, *model, T_w_c))
      out.push_back(edge(v.edge_id, v.a_px, v.b_px));
    return out;
  }
};

LineTrackTruthSummary trackBox(const BoxWorld& world, const std::string& tracker,
                               const Vector3d& truth_offset) {
  LineTrackerOptions options;
  options.tracker = tracker;
  const std::unique_ptr<LineTracker> t = createLineTracker(world.camera, options);
  LineTrackTruth score;
  for (int k = 0; k < 12; ++k) {
    const Eigen::Isometry3d T_w_c = BoxWorld::lookAt(Vector3d(0, -0.6 + 0.1 * k, 2.2));
    Eigen::Isometry3d T_truth = T_w_c;
    T_truth.translation() += truth_offset;
    score.addFrame(t->track(world.render(T_w_c), 0.05 * k), world.truth(T_truth));
  }
  return score.summarise();
}

}  // namespace

TEST(LineTrackTruth, TrackedBoxEdgesLieOnTheirTrueEdges) {
  const BoxWorld world;
  for (const std::string tracker : {"flow", "descriptor"}) {
    const LineTrackTruthSummary s = trackBox(world, tracker, Vector3d::Zero());
    EXPECT_GE(s.lines_per_frame, 5) << tracker;
    // Every detected line is a box edge; LSD is accurate to about a pixel.
    EXPECT_GT(s.associated_fraction, 0.9) << tracker;
    EXPECT_LT(s.median_endpoint_distance_px, 1.5) << tracker;
    EXPECT_GT(s.correct_fraction, 0.95) << tracker;
    EXPECT_GT(s.evaluated_tracks, 3u) << tracker;
  }
  // The truth projected from a camera 10 cm off (about 11 px at 4 m): no longer on the lines.
  EXPECT_LT(trackBox(world, "flow", Vector3d(0, 0.1, 0.1)).associated_fraction, 0.2);
}
